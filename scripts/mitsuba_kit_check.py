#!/usr/bin/env python3
"""The Mitsuba comparison kit's scenes rendered by Sahara from their Mitsuba 3 XML, against Mitsuba.

The kit (`../shared/compare/mitsuba`, its README.md) describes two scenes once, `dragon_glossy` and
`sponza_sun`, and writes each as a Mitsuba 3 XML file and as a Sahara TOML file. Here the kit's own
`scenes.py` writes them at a reduced size (the kit's film divided by --scale), Mitsuba 3 renders each
XML file as the reference (two halves of --ref-spp / 2 samples, seeds 1 and 2: their difference
measures the reference's own noise), and Sahara renders the same XML file (`sahara render NAME.xml`),
two halves of --spp / 2 samples. Nothing of the TOML file is used: the kit's conventions (Mitsuba's
`max_depth` D is Sahara's D - 1, `twosided` diffuse and conductors, the black one-sided area light,
`face_normals`, the thin lens, the box filter and independent sampler) have to come out of the XML
reader.

Printed per scene: the image mean per channel (Sahara, Mitsuba, relative difference and its z-score:
the difference over its standard error from the four halves) and the 8 x 8-pixel blocks (grey = mean
of R, G, B): z = block difference / its standard error (pure noise gives mean z^2 near 1 and almost no
|z| > 4) and the test's measure, |difference| / (reference + 0.02) per block and channel (its 90th
percentile and maximum).

With --test-data, the files of the Rust test `crates/sahara-formats/tests/formats/mitsuba_kit.rs` are
written into crates/sahara-formats/tests/mitsuba_kit/: each scene's XML with its meshes named through
the parameter `$scenes` (default: the shared scenes beside the workspace, `../shared/scenes`; the test
sets it from `$SAHARA_SCENES`), and the Mitsuba reference as a half-float EXR. The kit reads Sponza
from a flat PLY it writes (positions and triangles of `sponza.obj`); the test's XML reads `sponza.obj`
itself with `face_normals` (the same triangles, flat shaded), so that nothing generated is needed.
Sahara is run on that file too, against the same reference.

usage (Mitsuba 3.9.1 from PyPI: `python3 -m venv V && V/bin/pip install mitsuba==3.9.1 numpy OpenEXR`;
`cargo build --release` first):
    V/bin/python scripts/mitsuba_kit_check.py [--kit DIR] [--scale 4] [--ref-spp 16384] [--spp 1024]
                                              [--variant scalar_rgb] [--work DIR] [--only NAME,...]
                                              [--test-data] [--refs-only] [--test-noise N] [--test-spp 256]
--refs-only renders (or reuses, from --work) the references and skips Sahara's 1024-spp comparison;
--test-noise N renders the test's XML with Sahara at --test-spp for seeds 1..N and prints the spread of
the test's measures against the stored reference, which is what the test's tolerances are set from.
The meshes are read from $SAHARA_SCENES, else ../shared/scenes beside the repository; Sahara is
$SAHARA, else target/release/sahara.
"""
import argparse
import importlib.util
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAHARA = os.environ.get("SAHARA") or os.path.join(ROOT, "target", "release", "sahara")
TEST_DATA = os.path.join(ROOT, "crates", "sahara-formats", "tests", "mitsuba_kit")
SCENES = os.environ.get("SAHARA_SCENES") or os.path.join(ROOT, "..", "shared", "scenes")
# The test data's folder to the shared scenes, for the XML files' default of $scenes.
SCENES_FROM_TEST_DATA = "../../../../../shared/scenes"
BLOCK = 8


def kit_module(kit):
    """The kit's scenes.py, imported, reading the meshes from SCENES."""
    spec = importlib.util.spec_from_file_location("kit_scenes", os.path.join(kit, "scenes.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.SCENES_DIR = os.path.abspath(SCENES)
    return mod


def portable(xml_text, name):
    """The kit's XML with its absolute mesh paths replaced by `$scenes/...` (and a default for it)."""
    scenes = os.path.abspath(SCENES)
    text = xml_text.replace(f'value="{os.path.join(scenes, "dragon", "dragon.ply")}"',
                            'value="$scenes/dragon/dragon.ply"')
    text = re.sub(r'<shape type="ply"><string name="filename" value="[^"]*sponza_flat\.ply"/>',
                  '<shape type="obj"><string name="filename" value="$scenes/sponza/sponza.obj"/>', text)
    assert scenes not in text and "_flat.ply" not in text, "an absolute mesh path is left"
    head = (f"<!-- {name}: the Mitsuba comparison kit's scene (its scenes.py), written by\n"
            f"     scripts/mitsuba_kit_check.py; {name}.exr is Mitsuba 3's rendering of the kit's file.\n"
            f"     The meshes are read from $scenes: -D scenes=DIR to read them elsewhere. -->\n")
    text = text.replace('<scene version="3.0.0">',
                        f'<scene version="3.0.0">\n  <default name="scenes" value="{SCENES_FROM_TEST_DATA}"/>', 1)
    return head + text


def load_exr(path):
    import OpenEXR
    with OpenEXR.File(path) as f:
        ch = f.parts[0].channels
        if "RGB" in ch:
            return np.asarray(ch["RGB"].pixels, dtype=np.float64)[..., :3]
        if "RGBA" in ch:
            return np.asarray(ch["RGBA"].pixels, dtype=np.float64)[..., :3]
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def sahara(xml, out, spp, seed, defines=()):
    cmd = [SAHARA, "render", xml, "-o", out, "--spp", str(spp), "--seed", str(seed)]
    for d in defines:
        cmd += ["-D", d]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"sahara failed ({p.returncode}): {' '.join(cmd)}\n{p.stderr}")
    m = re.search(r"([0-9.]+) s render", p.stderr)
    warnings = [l for l in p.stderr.splitlines() if l.startswith("warning")]
    return load_exr(out), float(m.group(1)) if m else float("nan"), warnings


def compare(S, SA, SB, R, RA, RB):
    """Sahara (S = mean of halves SA, SB) against the reference R (halves RA, RB)."""
    floor = (1e-3 * np.abs(R) + 1e-6) ** 2
    var = ((SA - SB) ** 2 + (RA - RB) ** 2) / 4 + floor
    d = S - R
    n_pix = d.shape[0] * d.shape[1]
    out = {"mean_s": S.mean((0, 1)), "mean_r": R.mean((0, 1)),
           "rel": d.mean((0, 1)) / R.mean((0, 1)),
           "z_mean": d.mean((0, 1)) / np.sqrt(var.sum((0, 1))) * n_pix}
    h, w = (d.shape[0] // BLOCK) * BLOCK, (d.shape[1] // BLOCK) * BLOCK
    dg = d.mean(-1)[:h, :w]
    vg = (((SA - SB).mean(-1) ** 2 + (RA - RB).mean(-1) ** 2) / 4 + floor.mean(-1))[:h, :w]
    bd = dg.reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).mean((1, 3))
    bv = vg.reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).sum((1, 3)) / BLOCK ** 4
    z = bd / np.sqrt(bv)
    out.update(z2=float(np.mean(z ** 2)), z4=float(np.mean(np.abs(z) > 4)), zmax=float(np.abs(z).max()),
               blocks=z.size)
    # the Rust test's measure: per block and channel, |S - R| / (R + 0.02)
    blk = lambda a: a[:h, :w].reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, 3).mean((1, 3))
    e = np.sort((np.abs(blk(S) - blk(R)) / (blk(R) + 0.02)).ravel())
    out.update(p90=float(e[len(e) * 9 // 10]), emax=float(e[-1]))
    return out


def report(label, c):
    f = lambda a: ", ".join(f"{x:.5f}" for x in a)
    print(f"  {label}:")
    print(f"    mean R,G,B: Sahara {f(c['mean_s'])}, Mitsuba {f(c['mean_r'])}: "
          f"{', '.join(f'{x:+.2%}' for x in c['rel'])} (z {', '.join(f'{x:+.1f}' for x in c['z_mean'])})")
    print(f"    {c['blocks']} blocks of 8 x 8: mean z^2 {c['z2']:.2f}, |z| > 4 in {c['z4']:.1%}, "
          f"max |z| {c['zmax']:.1f}; |S - R| / (R + 0.02): 90% {c['p90']:.4f}, max {c['emax']:.4f}", flush=True)


def test_measures(img, ref):
    """The Rust test's measures: relative error of each channel's mean, and the 90th percentile and maximum of
    |S - R| / (R + 0.02) over the whole 8 x 8 blocks' channels."""
    mean = np.abs(img.mean((0, 1)) - ref.mean((0, 1))) / ref.mean((0, 1))
    h, w = (ref.shape[0] // BLOCK) * BLOCK, (ref.shape[1] // BLOCK) * BLOCK
    blk = lambda a: a[:h, :w].reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK, 3).mean((1, 3))
    e = np.sort((np.abs(blk(img) - blk(ref)) / (blk(ref) + 0.02)).ravel())
    return float(mean.max()), float(e[len(e) * 9 // 10]), float(e[-1])


def test_noise(name, xml, n, spp, work):
    """The test's measures for n seeds of Sahara at spp against the stored (half-float) reference."""
    ref = load_exr(os.path.join(TEST_DATA, f"{name}.exr"))
    rows, secs = [], []
    for seed in range(1, n + 1):
        img, s, _ = sahara(xml, os.path.join(work, f"{name}_test_{seed}.exr"), spp, seed,
                           (f"scenes={os.path.abspath(SCENES)}",))
        rows.append(test_measures(img, ref))
        secs.append(s)
    a = np.array(rows)
    print(f"  the test's measures, Sahara {spp} spp, {n} seeds ({np.median(secs):.1f} s render each): "
          f"worst channel's mean error median {np.median(a[:, 0]):.4f}, max {a[:, 0].max():.4f}; "
          f"blocks 90%: median {np.median(a[:, 1]):.4f}, max {a[:, 1].max():.4f}; "
          f"block max: median {np.median(a[:, 2]):.4f}, max {a[:, 2].max():.4f}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kit", default=os.path.join(ROOT, "..", "shared", "compare", "mitsuba"))
    ap.add_argument("--scale", type=int, default=4, help="the kit's film size divided by this (default 4)")
    ap.add_argument("--ref-spp", type=int, default=16384, help="Mitsuba's samples per pixel (default 16384)")
    ap.add_argument("--spp", type=int, default=1024, help="Sahara's samples per pixel (default 1024)")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--work", default=None, help="folder for the scenes and images (default: a new temporary one)")
    ap.add_argument("--test-data", action="store_true", help=f"write the test's XML and EXR files into {TEST_DATA}")
    ap.add_argument("--only", default="", help="comma-separated scene names")
    ap.add_argument("--refs-only", action="store_true", help="render (or reuse) the references only")
    ap.add_argument("--test-noise", type=int, default=0, metavar="N",
                    help="also render the test's XML at --test-spp with N seeds and print the spread of the "
                         "test's measures against the stored reference (to set its tolerances)")
    ap.add_argument("--test-spp", type=int, default=256, help="the test's samples per pixel (default 256)")
    args = ap.parse_args()
    if not args.refs_only and not os.path.exists(SAHARA):
        raise SystemExit(f"{SAHARA}: not found (cargo build --release)")
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(args.variant)
    dr.set_thread_count(os.cpu_count())
    work = args.work or tempfile.mkdtemp(prefix="sahara-mitsuba-kit-")
    os.makedirs(os.path.join(work, "scenes"), exist_ok=True)
    kit = kit_module(args.kit)
    names = args.only.split(",") if args.only else list(kit.SCENES)
    print(f"Mitsuba {mi.__version__} {args.variant} {args.ref_spp} spp vs Sahara {args.spp} spp; "
          f"the kit's scenes at 1/{args.scale} of their size; in {work}")
    for name in names:
        sc = dict(kit.SCENES[name])
        w, h = sc["film"]
        sc["film"] = [w // args.scale, h // args.scale]
        xml, _, _ = kit.write(name, sc, os.path.join(work, "scenes"))
        text = portable(open(xml).read(), name)
        port = os.path.join(work, "scenes", f"{name}_portable.xml")
        open(port, "w").write(text)

        # The reference, kept in the work folder: a second run with the same --work reuses it.
        cached = os.path.join(work, f"{name}_mitsuba_{args.variant}_{args.ref_spp}spp_1of{args.scale}.npz")
        t, reused = time.perf_counter(), os.path.exists(cached)
        if reused:
            with np.load(cached) as z:
                RA, RB = z["a"], z["b"]
        else:
            scene = mi.load_file(xml)
            RA, RB = (np.array(mi.render(scene, spp=args.ref_spp // 2, seed=seed), dtype=np.float64)[..., :3]
                      for seed in (1, 2))
            np.savez(cached, a=RA, b=RB)
        R = 0.5 * (RA + RB)
        ref_s = time.perf_counter() - t
        print(f"{name}: {sc['film'][0]} x {sc['film'][1]}, Mitsuba {args.ref_spp} spp "
              f"{'(reused)' if reused else f'in {ref_s:.0f} s'}, "
              f"own rms noise {np.sqrt(np.mean((RA - RB) ** 2) / 4):.5f}", flush=True)
        if args.test_data:
            os.makedirs(TEST_DATA, exist_ok=True)
            open(os.path.join(TEST_DATA, f"{name}.xml"), "w").write(text)
            # Half floats: three significant digits, far finer than the tolerances.
            bmp = mi.Bitmap(R.astype(np.float16), pixel_format=mi.Bitmap.PixelFormat.RGB)
            bmp.write(os.path.join(TEST_DATA, f"{name}.exr"))
        if args.test_noise:
            test_noise(name, port, args.test_noise, args.test_spp, work)
        if args.refs_only:
            continue

        for label, path, defines in (("the kit's XML", xml, ()),
                                     ("the test's XML", port, (f"scenes={os.path.abspath(SCENES)}",))):
            imgs, secs = [], 0.0
            for seed in (11, 12):
                img, s, warnings = sahara(path, os.path.join(work, f"{name}_sahara_{seed}.exr"), args.spp // 2,
                                          seed, defines)
                imgs.append(img)
                secs += s
            SA, SB = imgs
            print(f"  Sahara from {label} ({os.path.basename(path)}): {secs:.1f} s render; "
                  f"{len(warnings)} warning(s)" + "".join(f"\n    {w}" for w in warnings))
            report(f"Sahara {args.spp} spp vs Mitsuba {args.ref_spp} spp", compare(0.5 * (SA + SB), SA, SB, R, RA, RB))


if __name__ == "__main__":
    sys.exit(main())
