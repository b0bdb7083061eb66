#!/usr/bin/env python3
"""How many non-test source files name each material kind and light kind.

A kind is named by its enum variants (`Bsdf::CoatedDiffuse`,
`MaterialKind::CoatedDiffuse`, `Light::Spot`, `LightKind::Spot`, and
`Self::Spot` inside an `impl` of those enums), by its constructor
(`Material::diffuse`, `Light::spot`) or by its own struct type
(`AreaLight`, `EnvLight`). A plain word search overcounts: the bench's ray
set `Diffuse`, its camera's `Mirror` and prose use the same words. Comments
are left out (a doc link is not code that changes with the kind), and so is
test code: `tests.rs`, `tests/`, `benches/`, `examples/` and `#[cfg(test)]`
modules.

Usage: scripts/kind_files.py [--limit N] [--files] [--comments]
Run from the repository root. Exits 1 when a kind is named in more than
`--limit` files (6 by default).
"""
import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# kind -> the enum paths, constructors and struct names that name it.
MATERIALS = {
    "diffuse": (["Bsdf::Diffuse", "MaterialKind::Diffuse", "Material::diffuse"], []),
    "conductor": (["Bsdf::Conductor", "Bsdf::ComplexConductor", "MaterialKind::Conductor",
                   "Material::conductor"], []),
    "mirror": (["Bsdf::Mirror", "MaterialKind::Mirror", "Material::mirror"], []),
    "dielectric": (["Bsdf::Dielectric", "MaterialKind::Dielectric", "Material::glass"], []),
    "rough_dielectric": (["Bsdf::RoughDielectric", "MaterialKind::RoughDielectric",
                          "Material::rough_glass"], []),
    "thin_dielectric": (["Bsdf::ThinDielectric", "MaterialKind::ThinDielectric"], []),
    "metallic_roughness": (["Bsdf::MetallicRoughness", "MaterialKind::MetallicRoughness"], []),
    "coated_diffuse": (["Bsdf::CoatedDiffuse", "MaterialKind::CoatedDiffuse"], []),
    "emission": (["MaterialKind::Emission", "Material::emitter"], []),
}
LIGHTS = {
    "point": (["Light::Point", "LightKind::Point", "Light::point"], []),
    "spot": (["Light::Spot", "LightKind::Spot", "Light::spot"], []),
    "directional": (["Light::Directional", "LightKind::Directional", "Light::directional"], []),
    "area": (["LightKind::Area"], ["AreaLight"]),
    "environment": (["LightKind::Environment"], ["EnvLight"]),
}
ENUMS = ("Bsdf", "MaterialKind", "Light", "LightKind")


def source_files():
    for crate in sorted(os.listdir(os.path.join(ROOT, "crates"))):
        src = os.path.join(ROOT, "crates", crate, "src")
        for dirpath, dirnames, filenames in os.walk(src):
            dirnames[:] = [d for d in dirnames if d not in ("tests", "benches", "examples")]
            for name in sorted(filenames):
                if name.endswith(".rs") and name != "tests.rs" and not name.startswith("test_"):
                    yield os.path.join(dirpath, name)


def strip_comments(text):
    """Blank out // and /* */ comments, keeping string literals."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            i = n if j < 0 else j + 2
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def strip_test_modules(text):
    """Drop every `#[cfg(test)]` item (a module or a function) by brace matching."""
    while True:
        m = re.search(r"#\[cfg\(test\)\]\s*", text)
        if not m:
            return text
        start = m.start()
        brace = text.find("{", m.end())
        semi = text.find(";", m.end())
        if brace < 0 or (0 <= semi < brace):
            end = semi + 1  # `#[cfg(test)] mod tests;` or a `use`
        else:
            depth, end = 0, brace
            while end < len(text):
                if text[end] == "{":
                    depth += 1
                elif text[end] == "}":
                    depth -= 1
                    if depth == 0:
                        break
                end += 1
            end += 1
        text = text[:start] + text[end:]


def self_paths(text):
    """Rewrite `Self::X` inside `impl Enum` blocks to `Enum::X`."""
    out, current = [], None
    for line in text.split("\n"):
        m = re.match(r"impl(?:<[^>]*>)?\s+(?:[\w:]+\s+for\s+)?(\w+)\b", line)
        if m:
            current = m.group(1) if m.group(1) in ENUMS else None
        elif line.startswith("}"):
            current = None
        if current:
            line = re.sub(r"\bSelf::", current + "::", line)
        out.append(line)
    return "\n".join(out)


def count(table, files, comments):
    result = {}
    for kind, (paths, structs) in table.items():
        pats = [re.compile(r"\b" + re.escape(p) + r"\b") for p in paths]
        pats += [re.compile(r"\b" + re.escape(s) + r"\b") for s in structs]
        result[kind] = sorted(f for f, text in files.items() if any(p.search(text) for p in pats))
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=6)
    ap.add_argument("--files", action="store_true", help="list the files per kind")
    ap.add_argument("--comments", action="store_true", help="count comments too")
    a = ap.parse_args()
    files = {}
    for path in source_files():
        text = open(path, encoding="utf-8").read()
        if not a.comments:
            text = strip_comments(text)
        files[os.path.relpath(path, ROOT)] = self_paths(strip_test_modules(text))
    over = False
    for title, table in (("material", MATERIALS), ("light", LIGHTS)):
        for kind, hits in count(table, files, a.comments).items():
            flag = "  OVER" if len(hits) > a.limit else ""
            over |= bool(flag)
            print(f"{title:8} {kind:20} {len(hits):2} files{flag}")
            if a.files:
                for f in hits:
                    print(f"           {f}")
    sys.exit(1 if over else 0)


if __name__ == "__main__":
    main()
