#!/usr/bin/env python3
"""Benedikt Bitterli's scenes, as written for pbrt-v4, rendered by Sahara and held to Tungsten's renders.

A checkout of the pbrt-v4 versions of Bitterli's rendering resources (--bitterli DIR) holds, for each
scene, `<scene>/pbrt/scene-v4.pbrt`, its meshes and textures, its `LICENSE.txt`, and Tungsten's
converged render `TungstenRender.exr`. The scenes of GALLERY are held by the Rust test
`crates/sahara-formats/tests/formats/bitterli_gallery.rs`; this script makes its data and its
tolerances:

--write   copies each held scene's files (the .pbrt file(s), every mesh and image they name, and
          LICENSE.txt) into crates/sahara-formats/tests/bitterli/<scene>/ when they total at most
          --keep-mb (else the test reads the scene from $BITTERLI and skips without it), and writes
          there `reference.exr`: Tungsten's render box-filtered down by the scene's factor (half floats).
--seeds N renders each held scene with Sahara at the test's size and samples for seeds 1..N and prints
          each measure's mean and standard deviation, and the test's table of cases with the bounds
          mean +- 4 sigma (the test renders with seed 0, outside the measured ones).
--sheet   renders each held scene with seed 0 and writes docs/images/bitterli/<scene>.png (Sahara's
          image beside Tungsten's, with the measured ratio) and the table for docs/pbrt.md.
--survey  renders every scene of the checkout that Sahara reads (but those of SKIPPED) at an eighth
          of Tungsten's size and --survey-spp samples, and prints, per scene: complete or the files
          missing, the licence, the warnings, the time, the mean ratio and the block errors.
--causes  renders the variants of CAUSES (a scene's file with its missing textures replaced by the
          copies in the checkout's Tungsten files, or by black or white, or with one of its lights
          removed; written beside links to the scene's files in a temporary folder) at the survey's
          settings, with the same measures: how much of a difference each explains.
--variance renders veach-bidir (bdpt as the file asks, and path tracing) and the built-in Cornell box
          with 16 seeds each and prints bdpt's per-pixel variance over the path tracer's.
--mitsuba renders with Mitsuba 3 (`scalar_rgb`; pip install mitsuba==3.9.1) Bitterli's own Mitsuba
          file of the Cornell box at 4 and at 64 bounces, volumetric-caustic's pbrt file written
          for Mitsuba with and without its medium, veach-ajar's and veach-bidir's files (through
          scripts/pbrt_mitsuba.py; veach-ajar also with the floor of Tungsten's scene, more
          bounces, its missing images black and white) and water-caustic's without its water,
          against Tungsten's render and Sahara's; and the light water-caustic's camera sees
          through the waves, rendered by Sahara's camera paths, against Tungsten's.

The measures, as the test computes them: the image mean of each channel over Tungsten's (its ratio), and
the block error of blocks.rs, |mean of Sahara - mean of Tungsten| / (mean of Tungsten + 0.02) for every
whole 8 x 8 block and channel, of which the median and the 90th percentile are held.

usage (numpy, OpenEXR and pillow; `cargo build --release` first; Sahara is $SAHARA, else
target/release/sahara):
    python3 scripts/bitterli_gallery.py --bitterli DIR [--write] [--seeds 8] [--sheet]
                                        [--survey] [--survey-spp 256] [--causes] [--mitsuba]
                                        [--variance]
                                        [--only SCENE,...]
With none of --write, --seeds, --sheet, --survey, --causes, --mitsuba it does the first three.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAHARA = os.environ.get("SAHARA") or os.path.join(ROOT, "target", "release", "sahara")
TEST_DATA = os.path.join(ROOT, "crates", "sahara-formats", "tests", "bitterli")
IMAGES = os.path.join(ROOT, "docs", "images", "bitterli")
BLOCK = 8
TEST_SEED = 0

# The held cases: Tungsten's image is divided by `factor` on each side (an integer, so that the box
# filter is exact and the aspect ratio kept), Sahara renders `spp` samples per pixel with the
# integrator and depth the file asks for. `why` is the reason the ratio is what it is. A case is a
# scene's folder and its `scene-v4.pbrt`, unless it names another `scene` (folder) and `file`: a file
# that `derive` writes from the scene's files (see DERIVED), kept beside them.
GALLERY = {
    "cornell-box": dict(
        factor=8, spp=64,
        why="the file asks for `maxdepth 4` where Tungsten traced 64 bounces: 3-4 % of the light, "
            "most in red, is missing. Mitsuba 3 renders Bitterli's own Mitsuba file of the scene at "
            "max_depth 5 (4 bounces) to the same ratio, and at 65 to Tungsten's within 0.01 %"),
    "coffee": dict(
        factor=8, spp=64,
        why="nothing is approximated: the ratio is 1 within the noise"),
    "volumetric-caustic": dict(
        factor=8, spp=64,
        why="the box is filled with the file's medium (sigma_s 1, albedo 1) around a glass sphere "
            "and a 5 x 4 mm light. Sahara's image is brighter than Tungsten's and Mitsuba 3's volpath "
            "renders the same scene darker than Tungsten's (0.92, 0.95, 1.00, block median 0.22): with "
            "single scattering alone (no sphere) Sahara's image centre is the numerically integrated "
            "answer and Mitsuba's 11 % below it, and the gap widens with more bounces, so the bounds "
            "hold Sahara's image as it is. The mean rests on "
            "rare paths from the tiny light through the sphere, hence the wide bounds on the ratio"),
    "veach-mis": dict(
        factor=8, spp=64,
        why="the pbrt-v4 file is not the scene Tungsten rendered: its plates lack Tungsten's albedo "
            "of 0.3, are GGX where Tungsten's are Beckmann, and the file asks for `maxdepth 3` where "
            "Tungsten's image is direct light only. Mitsuba 3 renders the file as Sahara does "
            "(`--mitsuba`: image mean within 0.3 %, block error median 0.01), and the file with "
            "Tungsten's three settings (the next case) matches Tungsten's render"),
    "veach-mis-tungsten": dict(
        scene="veach-mis", file="scene-tungsten.xml", derive="veach-mis-tungsten",
        factor=8, spp=64,
        why="veach-mis with the three settings of Tungsten's scene that its pbrt-v4 file lacks, "
            "written as a Mitsuba 3 scene (`scene-tungsten.xml`, made from the pbrt file by this "
            "script): Beckmann plates of albedo 0.3, light that bounces once"),
    "veach-ajar": dict(
        factor=16, spp=64,
        # The file names two images that the collection does not have; Sahara reads each as grey.
        missing=["textures/landscape-with-a-lake.tga", "textures/Good Textures_005844.tga"],
        why="the floor of the file is the bare rough metal, where Tungsten's (as Bitterli's own "
            "Mitsuba file of the scene says) scales its reflection by a checkerboard of 0.8 and 0.2: "
            "Mitsuba 3 renders the file to Sahara's image (Sahara / Mitsuba 0.997, 1.002, 1.004) and, "
            "with that checkerboard added, to 1.01, 1.04, 1.09 of Tungsten's with block median 0.08. "
            "The rest is the two missing images (grey here; black gives 0.94-0.98, white 1.15-1.27 "
            "in Mitsuba) and `maxdepth 13` (64 bounces add 2 %). Path tracing at 64 samples leaves "
            "fireflies, hence the bounds"),
    "water-caustic": dict(
        factor=8, spp=32,
        # The light seen directly, 5 x 4 mm at a radiance of 5.4e5, covers half of one pixel of
        # Tungsten's 1024 x 1024 image (and holds infinity there, out of the half floats' range):
        # these pixels of Tungsten's size (x0, x1, y0, y1, ends excluded; the test's pixel of the
        # light and those around it) are left out of every measure, in both images.
        mask=(496, 520, 72, 96),
        why="the light seen directly (0.008 of a pixel at a radiance of 5.4e5: half of the "
            "image's red mean, found by a sample or not, and infinity in Tungsten's half floats) is "
            "left out of the measures. Tungsten's image also shows the light through the waves of the "
            "water (light, refraction, refraction, camera) in some 30 pixels, 7-9 % of the rest of "
            "its mean; Sahara's camera paths carry the same light there (17300 against 16300 in "
            "red, `distribution` at 4096 samples on that window of the full size), but a render "
            "at this size finds it once in some 65 (seed 4 of those measured) and then adds about 4 "
            "to the ratio: no bound on the ratio, the blocks hold the scene. Without those spots the image is 1.06, 1.02, "
            "0.98 of Tungsten's; without the water, Sahara's sppm renders the box as Mitsuba 3 "
            "does (0.998, 1.000, 0.999)"),
    "veach-bidir": dict(
        factor=16, spp=32,
        why="Mitsuba 3's path tracer renders the file to Sahara's image (Sahara's bdpt at 256 "
            "samples / Mitsuba at 4096: 1.000, 1.001, 1.001, block median 0.011), and Mitsuba's "
            "image is 1.012, 1.007, 1.003 of Tungsten's (1.02, 1.01, 1.01 at 64 bounces): the file "
            "and Tungsten's scene differ by 1-2 %"),
}

# Scenes left out of the survey: the held scenes whose files and Tungsten's scenes differ in ways
# measured apart (--mitsuba), and those made for other integrators than path tracing (--seeds).
SKIPPED = {"veach-mis", "veach-ajar", "water-caustic", "veach-bidir"}

# Scenes whose files are complete and read, but not held, and why.
NOT_HELD = {
    "hair-curl": "the file keeps one `curve` of the hair (the other `Import`s are commented out) and "
                 "Sahara skips curves: its image is black where Tungsten's shows a head of hair",
}

# Variants of scenes not held, each (scene, name, what to change): `tungsten:` replaces a texture by
# the file of that name in the scene's `tungsten/textures/`, `black` / `white` by a plain image,
# `no-sun` / `no-sky` removes the `distant` / the `infinite` light.
CAUSES = [
    ("bathroom", "Tungsten's textures", {"wood": "tungsten:wood.jpg", "wood2": "tungsten:wood2.jpg",
                                         "marble": "tungsten:marble.jpg",
                                         "wallpaper-2": "tungsten:wallpaper-2.jpg"}),
    ("classroom", "Tungsten's blackboard", {"blackboard": "tungsten:blackboard.jpg"}),
    ("classroom", "sun alone", "no-sky"),
    ("classroom", "sky alone", "no-sun"),
    ("dining-room", "picture black", {"picture3": "black"}),
    ("dining-room", "picture white", {"picture3": "white"}),
    ("dining-room", "sun alone", "no-sky"),
    ("dining-room", "sky alone", "no-sun"),
    ("kitchen", "wood black", {"wood": "black"}),
    ("kitchen", "wood white", {"wood": "white"}),
    ("staircase", "textures black", {n: "black" for n in ["Painting2", "Painting3", "Fabric", "WoodChair"]}),
    ("staircase", "textures white", {n: "white" for n in ["Painting2", "Painting3", "Fabric", "WoodChair"]}),
    ("staircase2", "wood black", {"wood5": "black"}),
    ("staircase2", "wood white", {"wood5": "white"}),
]
SUN_RE = re.compile(r'LightSource "distant"\n(\s+"[^\n]*\n){3}')
SKY_RE = re.compile(r'LightSource "infinite"\n\s+"string filename" "[^"]*"\n')

FILE_RE = re.compile(r'"([^"\n]+\.(?:ply|obj|png|jpg|jpeg|exr|tga|pfm|hdr|pbrt|spd|bmp|gz))"', re.I)
INCLUDE_RE = re.compile(r'^\s*(?:Include|Import)\s+"([^"]+)"', re.M)
FILM_RE = re.compile(r'Film\s+"[^"]*"\s*(?:#[^\n]*)?\s*"string filename"\s*\[?\s*"([^"]+)"')


def strip_comments(text):
    return "\n".join(line.split("#", 1)[0] for line in text.split("\n"))


def references(pbrt):
    """Every file `pbrt` names (and the files it includes name), relative to its folder: (present,
    missing). The film's output name is not one."""
    folder = os.path.dirname(pbrt)
    present, missing, seen, todo = [], [], set(), [os.path.basename(pbrt)]
    while todo:
        rel = todo.pop()
        text = open(os.path.join(folder, rel), errors="replace").read()
        outputs = set(FILM_RE.findall(text))
        text = strip_comments(text)
        names = FILE_RE.findall(text) + INCLUDE_RE.findall(text)
        for name in names:
            if name in seen or name in outputs:
                continue
            seen.add(name)
            if os.path.isfile(os.path.join(folder, name)):
                present.append(name)
                if name.endswith(".pbrt"):
                    todo.append(name)
            else:
                missing.append(name)
    return present, missing


def licence(folder):
    path = os.path.join(folder, "LICENSE.txt")
    if not os.path.exists(path):
        return None
    text = open(path, errors="replace").read()
    if "CC0" in text:
        return "CC0"
    if "CC-BY" in text:
        return "CC-BY"
    return None


def read_exr(path):
    import OpenEXR
    with OpenEXR.File(path) as f:
        ch = f.parts[0].channels
        if "RGB" in ch:
            return np.asarray(ch["RGB"].pixels, dtype=np.float64)[..., :3]
        if "RGBA" in ch:
            return np.asarray(ch["RGBA"].pixels, dtype=np.float64)[..., :3]
        return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def write_exr(path, rgb):
    import OpenEXR
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File(header, {"RGB": np.ascontiguousarray(rgb, dtype=np.float16)}).write(path)


def box_down(img, k):
    h, w, _ = img.shape
    assert h % k == 0 and w % k == 0, f"{w} x {h} is not a multiple of {k}"
    return img.reshape(h // k, k, w // k, k, 3).mean(axis=(1, 3))


def test_mask(scene):
    """The pixels of the test's image left out of the measures, (x0, x1, y0, y1) with the ends
    excluded, or None: the scene's `mask` in Tungsten's pixels divided by its factor."""
    m = GALLERY[scene].get("mask")
    if m is None:
        return None
    k = GALLERY[scene]["factor"]
    return (m[0] // k, -(-m[1] // k), m[2] // k, -(-m[3] // k))


def measures(img, ref, mask=None):
    """(ratio per channel, block error median, block error 90th percentile), as the test has them;
    the pixels of `mask` (x0, x1, y0, y1) are zero in both images."""
    if mask is not None:
        img, ref = img.copy(), ref.copy()
        for a in (img, ref):
            a[mask[2]:mask[3], mask[0]:mask[1]] = 0.0
    ratio = img.reshape(-1, 3).mean(0) / ref.reshape(-1, 3).mean(0)
    h, w, _ = img.shape
    hb, wb = h // BLOCK, w // BLOCK
    a = img[:hb * BLOCK, :wb * BLOCK].reshape(hb, BLOCK, wb, BLOCK, 3).mean(axis=(1, 3))
    b = ref[:hb * BLOCK, :wb * BLOCK].reshape(hb, BLOCK, wb, BLOCK, 3).mean(axis=(1, 3))
    e = np.sort((np.abs(a - b) / (b + 0.02)).ravel())
    return ratio, e[len(e) // 2], e[len(e) * 9 // 10], e


def render(pbrt, w, h, spp, seed, out):
    cmd = [SAHARA, "render", pbrt, "--width", str(w), "--height", str(h), "--spp", str(spp),
           "--seed", str(seed), "-o", out]
    t = time.time()
    r = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.time() - t
    warnings = [line for line in r.stderr.splitlines() if line.startswith(("warning", "error"))]
    if r.returncode != 0:
        return None, dt, warnings
    return read_exr(out), dt, warnings


def scene_file(bitterli, scene):
    return os.path.join(bitterli, scene, "pbrt", "scene-v4.pbrt")


def folder_of(case):
    """The scene folder of a held case."""
    return GALLERY[case].get("scene", case)


def case_file(bitterli, case):
    """The file a held case renders: the scene's pbrt file in the checkout, or the file derived from
    it in the test data (written by --write)."""
    c = GALLERY[case]
    if "derive" in c:
        return os.path.join(TEST_DATA, folder_of(case), c["file"])
    return scene_file(bitterli, folder_of(case))


def held_size(bitterli, case):
    """(reference image, test width, height) of a held case."""
    k = GALLERY[case]["factor"]
    scene = folder_of(case)
    ref = box_down(read_exr(os.path.join(bitterli, scene, "pbrt", "TungstenRender.exr")), k)
    # As stored (half floats), so that the measures here are the test's.
    ref = ref.astype(np.float16).astype(np.float64)
    return ref, ref.shape[1], ref.shape[0]


def check_held(bitterli, scene):
    pbrt = scene_file(bitterli, scene)
    present, missing = references(pbrt)
    missing = [f for f in missing if f not in GALLERY[scene].get("missing", [])]
    if missing:
        sys.exit(f"{scene}: held, but its files are incomplete: {missing}")
    if licence(os.path.dirname(pbrt)) is None:
        sys.exit(f"{scene}: held, but its licence does not allow redistribution")
    return present


def write(bitterli, cases, keep_mb):
    # Derived files last: a scene's folder is written anew first.
    for case in sorted(cases, key=lambda c: "derive" in GALLERY[c]):
        if "derive" in GALLERY[case]:
            path = case_file(bitterli, case)
            DERIVED[GALLERY[case]["derive"]](scene_file(bitterli, folder_of(case)), path)
            print(f"{case}: wrote {os.path.relpath(path, ROOT)} and its meshes")
            continue
        scene = case
        present = check_held(bitterli, scene)
        src = os.path.dirname(scene_file(bitterli, scene))
        dst = os.path.join(TEST_DATA, scene)
        if os.path.isdir(dst):
            shutil.rmtree(dst)
        os.makedirs(dst)
        files = ["scene-v4.pbrt", "LICENSE.txt"] + present
        size = sum(os.path.getsize(os.path.join(src, f)) for f in files)
        kept = size <= keep_mb * 1e6
        if kept:
            for f in files:
                os.makedirs(os.path.dirname(os.path.join(dst, f)), exist_ok=True)
                shutil.copyfile(os.path.join(src, f), os.path.join(dst, f))
        else:
            shutil.copyfile(os.path.join(src, "LICENSE.txt"), os.path.join(dst, "LICENSE.txt"))
        ref, w, h = held_size(bitterli, scene)
        write_exr(os.path.join(dst, "reference.exr"), ref)
        print(f"{scene}: {len(files)} files, {size / 1e6:.2f} MB, "
              f"{'kept' if kept else 'not kept (read from $BITTERLI)'}; reference {w} x {h}")


def spread(bitterli, scenes, seeds, work):
    rows = []
    for scene in scenes:
        ref, w, h = held_size(bitterli, scene)
        spp = GALLERY[scene]["spp"]
        runs, times = [], []
        for seed in list(range(1, seeds + 1)) + [TEST_SEED]:
            img, dt, warnings = render(case_file(bitterli, scene), w, h, spp, seed,
                                       os.path.join(work, f"{scene}-{seed}.exr"))
            if img is None:
                sys.exit(f"{scene}: Sahara failed: {warnings}")
            ratio, p50, p90, _ = measures(img, ref, test_mask(scene))
            runs.append(np.array([*ratio, p50, p90]))
            times.append(dt)
        m = np.array(runs[:-1])
        mean, sd = m.mean(0), m.std(0, ddof=1)
        test = runs[-1]
        inside = np.all(np.abs(test - mean) <= 4 * sd)
        print(f"{scene}: {w} x {h}, {spp} spp, {seeds} seeds, {np.mean(times):.1f} s a render")
        for i, name in enumerate(["ratio R", "ratio G", "ratio B", "block median", "block p90"]):
            print(f"  {name:12s} mean {mean[i]:.4f}  sd {sd[i]:.4f}  bounds {mean[i] - 4 * sd[i]:.4f} .. "
                  f"{mean[i] + 4 * sd[i]:.4f}  seed {TEST_SEED}: {test[i]:.4f}")
        print(f"  seed {TEST_SEED} {'within' if inside else 'OUTSIDE'} the bounds")
        file = GALLERY[scene].get("file", "scene-v4.pbrt")
        kept = os.path.exists(os.path.join(TEST_DATA, folder_of(scene), file))
        rows.append((scene, kept, w, h, spp, mean, 4 * sd))
    print("\n// The test's table (bitterli_gallery.rs, CASES):")
    for scene, kept, w, h, spp, mean, tol in rows:
        why = GALLERY[scene]["why"]
        print(f"    // {scene}: {why}.")
        print("    Case {")
        print(f'        name: "{scene}",')
        print(f'        scene: "{folder_of(scene)}",')
        print(f'        file: "{GALLERY[scene].get("file", "scene-v4.pbrt")}",')
        print(f"        kept: {'true' if kept else 'false'},")
        print(f"        width: {w},\n        height: {h},\n        spp: {spp},")
        mask = test_mask(scene)
        print(f"        mask: {'None' if mask is None else f'Some({list(mask)})'},")
        print(f"        ratio: [{mean[0]:.4f}, {mean[1]:.4f}, {mean[2]:.4f}],")
        print(f"        ratio_tol: [{tol[0]:.4f}, {tol[1]:.4f}, {tol[2]:.4f}],")
        print(f"        block_p50: ({mean[3]:.4f}, {tol[3]:.4f}),")
        print(f"        block_p90: ({mean[4]:.4f}, {tol[4]:.4f}),")
        print("    },")


def srgb8(x):
    x = np.clip(x, 0.0, 1.0)
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (x * 255 + 0.5).astype(np.uint8)


def sheet(bitterli, scenes, work):
    from PIL import Image, ImageDraw
    os.makedirs(IMAGES, exist_ok=True)
    print("| Sahara, Tungsten | scene | ratio R, G, B | block error median, 90 % |")
    print("|---|---|---|---|")
    for scene in scenes:
        ref, w, h = held_size(bitterli, scene)
        img, _, _ = render(case_file(bitterli, scene), w, h, GALLERY[scene]["spp"], TEST_SEED,
                           os.path.join(work, f"{scene}-sheet.exr"))
        ratio, p50, p90, _ = measures(img, ref, test_mask(scene))
        gap, caption = 4, 28
        # At least as wide as the caption.
        pic = Image.new("RGB", (max(2 * w + gap, 176), h + caption), (255, 255, 255))
        pic.paste(Image.fromarray(srgb8(img)), (0, 0))
        pic.paste(Image.fromarray(srgb8(ref)), (w + gap, 0))
        draw = ImageDraw.Draw(pic)
        draw.text((2, h + 2), "Sahara", fill=(0, 0, 0))
        draw.text((w + gap + 2, h + 2), "Tungsten", fill=(0, 0, 0))
        draw.text((2, h + 15), f"mean ratio {ratio[0]:.3f}, {ratio[1]:.3f}, {ratio[2]:.3f}", fill=(0, 0, 0))
        pic.save(os.path.join(IMAGES, f"{scene}.png"), optimize=True)
        print(f"| ![{scene}](images/bitterli/{scene}.png) | `{scene}` | "
              f"{ratio[0]:.3f}, {ratio[1]:.3f}, {ratio[2]:.3f} | {p50:.3f}, {p90:.3f} |")


def survey(bitterli, spp, only, work):
    for scene in sorted(os.listdir(bitterli)):
        pbrt = scene_file(bitterli, scene)
        if scene in SKIPPED or not os.path.exists(pbrt) or (only and scene not in only):
            continue
        present, missing = references(pbrt)
        ref = read_exr(os.path.join(bitterli, scene, "pbrt", "TungstenRender.exr"))
        ref = box_down(ref, 8)
        h, w, _ = ref.shape
        img, dt, warnings = render(pbrt, w, h, spp, TEST_SEED, os.path.join(work, f"{scene}-survey.exr"))
        lic = licence(os.path.dirname(pbrt)) or "none"
        state = "complete" if not missing else f"missing {len(missing)}: {', '.join(missing)}"
        print(f"== {scene}: {state}; licence {lic}; {w} x {h}, {spp} spp, {dt:.1f} s")
        for line in warnings:
            print(f"   {line}")
        if img is not None:
            ratio, p50, p90, _ = measures(img, ref)
            print(f"   ratio {ratio[0]:.3f} {ratio[1]:.3f} {ratio[2]:.3f}, "
                  f"block error median {p50:.3f}, 90 % {p90:.3f}")


def variant_file(bitterli, scene, change, work):
    """The scene's file changed as `change` says, beside links to its files in `work`."""
    src = os.path.dirname(scene_file(bitterli, scene))
    folder = os.path.join(work, scene)
    if not os.path.isdir(folder):
        os.makedirs(folder)
        for entry in os.listdir(src):
            os.symlink(os.path.join(src, entry), os.path.join(folder, entry))
    text = open(scene_file(bitterli, scene)).read()
    if change == "no-sun":
        changed = SUN_RE.sub("", text)
    elif change == "no-sky":
        changed = SKY_RE.sub("", text)
    else:
        from PIL import Image
        changed = text
        for name, by in change.items():
            if by.startswith("tungsten:"):
                path = os.path.join(bitterli, scene, "tungsten", "textures", by.split(":", 1)[1])
            else:
                path = os.path.join(work, f"{by}.png")
                level = 0 if by == "black" else 255
                Image.new("RGB", (4, 4), (level, level, level)).save(path)
            changed = changed.replace(f'"textures/{name}.tga"', f'"{path}"')
    assert changed != text, (scene, change)
    path = os.path.join(folder, f"variant-{len(os.listdir(folder))}.pbrt")
    open(path, "w").write(changed)
    return path


def causes(bitterli, spp, only, work):
    for scene, name, change in CAUSES:
        if only and scene not in only:
            continue
        ref = box_down(read_exr(os.path.join(bitterli, scene, "pbrt", "TungstenRender.exr")), 8)
        h, w, _ = ref.shape
        pbrt = variant_file(bitterli, scene, change, work)
        img, dt, warnings = render(pbrt, w, h, spp, 1, os.path.join(work, "variant.exr"))
        if img is None:
            sys.exit(f"{scene}, {name}: Sahara failed: {warnings}")
        ratio, p50, p90, _ = measures(img, ref)
        print(f"{scene}, {name}: ratio {ratio[0]:.3f} {ratio[1]:.3f} {ratio[2]:.3f}, "
              f"block error median {p50:.3f}, 90 % {p90:.3f} ({w} x {h}, {spp} spp, {dt:.0f} s)")


def mitsuba_volumetric_caustic(mi, medium, spp, size):
    """volumetric-caustic's pbrt file as a Mitsuba 3 scene: the Cornell box of 2 x 2 x 2 around a
    glass sphere, lit by a 5 x 4 mm quad under the ceiling, seen through its open front, and filled
    with a medium of sigma_s 1 and sigma_a 0 (a null-bsdf cube 1 cm inside the walls) if `medium`.
    pbrt's `maxdepth 7` is Mitsuba's `max_depth` 8. (With the cube 1e-4 inside the walls, Mitsuba 3.9.1
    renders the box 1.5-1.75x darker than Sahara, which renders both forms alike within 4 %: paths that
    leave a wall skip the boundary, a hair away, and cross the box as if in vacuum.)"""
    T = mi.ScalarTransform4f

    def diffuse(rgb):
        return {"type": "twosided",
                "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}}}
    white = [0.725, 0.71, 0.68]
    d = {
        "type": "scene",
        "integrator": {"type": "volpath" if medium else "path", "max_depth": 8},
        "sensor": {"type": "perspective", "fov": 19.5, "fov_axis": "smaller",
                   "to_world": T().look_at(origin=[0, 1, 7], target=[0, 1, 0], up=[0, 1, 0]),
                   "sampler": {"type": "independent", "sample_count": spp},
                   "film": {"type": "hdrfilm", "width": size, "height": size,
                            "rfilter": {"type": "tent"}, "pixel_format": "rgb"}},
        "floor": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90), "bsdf": diffuse(white)},
        "ceiling": {"type": "rectangle", "to_world": T().translate([0, 2, 0]).rotate([1, 0, 0], 90),
                    "bsdf": diffuse(white)},
        "back": {"type": "rectangle", "to_world": T().translate([0, 1, -1]), "bsdf": diffuse(white)},
        "left": {"type": "rectangle", "to_world": T().translate([-1, 1, 0]).rotate([0, 1, 0], 90),
                 "bsdf": diffuse([0.63, 0.065, 0.05])},
        "right": {"type": "rectangle", "to_world": T().translate([1, 1, 0]).rotate([0, 1, 0], -90),
                  "bsdf": diffuse([0.14, 0.45, 0.091])},
        "light": {"type": "rectangle",
                  "to_world": T().translate([-0.005, 1.98, -0.03]).rotate([1, 0, 0], 90)
                  .scale([0.0025, 0.002, 1]),
                  "emitter": {"type": "area",
                              "radiance": {"type": "rgb", "value": [541126.75, 381971.8, 127323.94]}},
                  "bsdf": diffuse([0, 0, 0])},
    }
    sphere = {"type": "sphere", "center": [-0.22827, 1.2, 0.152505], "radius": 0.3,
              "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}}
    if medium:
        gas = {"type": "homogeneous", "albedo": {"type": "rgb", "value": [1, 1, 1]}, "sigma_t": 1.0}
        e = 1e-2
        d["gas"] = {"type": "cube", "to_world": T().translate([0, 1, 0]).scale([1 - e, 1 - e, 1 - e]),
                    "bsdf": {"type": "null"}, "interior": gas}
        sphere["exterior"] = gas
        d["light"]["exterior"] = gas
    d["sphere"] = sphere
    return mi.load_dict(d)


def mitsuba_checks(bitterli, work, only, spp=256):
    import mitsuba as mi
    mi.set_variant("scalar_rgb")

    def line(label, img, ref):
        ratio, p50, p90, _ = measures(img, ref)
        print(f"  {label}: ratio {ratio[0]:.4f} {ratio[1]:.4f} {ratio[2]:.4f}, "
              f"block error median {p50:.3f}, 90 % {p90:.3f}")

    for scene in [s for s in ["cornell-box", "volumetric-caustic", "veach-mis"] if not only or s in only]:
        ref = box_down(read_exr(os.path.join(bitterli, scene, "pbrt", "TungstenRender.exr")), 8)
        h, w, _ = ref.shape
        sahara, _, _ = render(scene_file(bitterli, scene), w, h, spp, 0, os.path.join(work, "s.exr"))
        print(f"{scene}, {w} x {h}, {spp} spp:")
        line("Sahara / Tungsten", sahara, ref)
        if scene == "cornell-box":
            xml = os.path.join(bitterli, scene, "mitsuba", "scene_v3.xml")
            for depth in ["5", "65"]:
                s = mi.load_file(xml, max_depth=depth, spp=str(spp), resx=str(w), resy=str(h))
                img = np.asarray(mi.render(s, spp=spp), dtype=np.float64)[..., :3]
                line(f"Mitsuba max_depth {depth} / Tungsten", img, ref)
                line(f"Sahara / Mitsuba max_depth {depth}", sahara, img)
        elif scene == "veach-mis":
            # The pbrt file's own scene, and with Tungsten's settings, both rendered by Mitsuba.
            for as_tungsten in (False, True):
                xml = os.path.join(work, "veach-mis", f"mitsuba-{as_tungsten}.xml")
                veach_mis_tungsten(scene_file(bitterli, scene), xml, as_tungsten)
                text = open(xml).read().replace('"1280"', f'"{w}"').replace('"720"', f'"{h}"')
                open(xml, "w").write(text)
                img = np.asarray(mi.render(mi.load_file(xml), spp=4 * spp), dtype=np.float64)[..., :3]
                name = "with Tungsten's settings" if as_tungsten else "of the pbrt file"
                line(f"Mitsuba {name}, {4 * spp} spp / Tungsten", img, ref)
                if not as_tungsten:
                    line(f"Sahara / Mitsuba {name}", sahara, img)
        else:
            for medium, mspp in [(False, spp), (True, 2 * spp)]:
                img = mi.render(mitsuba_volumetric_caustic(mi, medium, mspp, w), spp=mspp)
                img = np.asarray(img, dtype=np.float64)[..., :3]
                name = "with its medium" if medium else "without a medium"
                line(f"Mitsuba {name}, {mspp} spp / Tungsten", img, ref)
                line(f"Sahara / Mitsuba {name}", sahara, img)
    held_file_checks(bitterli, work, mi, line)


def mitsuba_of(mi, pbrt, spp, w, h, work, depth=None, textures=None, edit=None):
    """Mitsuba 3's image of a pbrt file (scripts/pbrt_mitsuba.py), `edit` applied to its dict."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import pbrt_mitsuba
    d = pbrt_mitsuba.scene(pbrt, spp, w, h, work, depth, textures)
    if edit:
        edit(d)
    return np.asarray(mi.render(mi.load_dict(d), spp=spp), dtype=np.float64)[..., :3]


def floor_checkerboard(mi):
    """veach-ajar's floor as Bitterli's own Mitsuba file of the scene has it: its reflection scaled
    by a checkerboard of 0.8 and 0.2, 20 x 80 checks over its uv square."""
    def edit(d):
        for shape in d.values():
            if isinstance(shape, dict) and shape.get("filename", "").endswith("Mesh011.ply"):
                shape["bsdf"]["bsdf"]["specular_reflectance"] = {
                    "type": "checkerboard", "color0": {"type": "rgb", "value": [0.8] * 3},
                    "color1": {"type": "rgb", "value": [0.2] * 3},
                    "to_uv": mi.ScalarTransform4f().scale([20, 80, 1])}
    return edit


def held_file_checks(bitterli, work, mi, line):
    """The figures behind the reasons of veach-ajar, veach-bidir and water-caustic: the files
    rendered by Mitsuba 3 (as they are, and changed as Tungsten's scenes differ) and by Sahara."""
    def tungsten(scene, k):
        ref = read_exr(os.path.join(bitterli, scene, "pbrt", "TungstenRender.exr"))
        return box_down(np.where(np.isfinite(ref), ref, 0.0), k)

    # veach-ajar at 80 x 45: the file as it is (path tracing, maxdepth 13), the floor's
    # checkerboard, 64 bounces, the two missing images black and white.
    pbrt = scene_file(bitterli, "veach-ajar")
    ref = tungsten("veach-ajar", 16)
    h, w, _ = ref.shape
    print(f"veach-ajar, {w} x {h}: Mitsuba 512 spp, Sahara 1024 spp")
    sahara, _, _ = render(pbrt, w, h, 1024, 1, os.path.join(work, "s.exr"))
    file_img = mitsuba_of(mi, pbrt, 512, w, h, work)
    line("Sahara / Mitsuba, the file", sahara, file_img)
    line("Sahara / Tungsten", sahara, ref)
    line("Mitsuba, the file / Tungsten", file_img, ref)
    floor = floor_checkerboard(mi)
    line("Mitsuba, the floor's checkerboard / Tungsten",
         mitsuba_of(mi, pbrt, 512, w, h, work, edit=floor), ref)
    line("Mitsuba, the floor's checkerboard, 64 bounces / Tungsten",
         mitsuba_of(mi, pbrt, 512, w, h, work, depth=64, edit=floor), ref)
    images = ("Texture01", "Texture02")
    for level in (0.0, 1.0):
        img = mitsuba_of(mi, pbrt, 512, w, h, work, depth=64, edit=floor,
                         textures={t: level for t in images})
        line(f"Mitsuba, the floor's checkerboard, 64 bounces, missing images {level:g} / Tungsten",
             img, ref)

    # veach-bidir at 64 x 64: Sahara's bdpt against Mitsuba's path tracer, at the file's
    # maxdepth 7 and at 64 bounces.
    pbrt = scene_file(bitterli, "veach-bidir")
    ref = tungsten("veach-bidir", 16)
    h, w, _ = ref.shape
    print(f"veach-bidir, {w} x {h}: Mitsuba 4096 spp, Sahara 256 spp")
    sahara, _, _ = render(pbrt, w, h, 256, 1, os.path.join(work, "s.exr"))
    file_img = mitsuba_of(mi, pbrt, 4096, w, h, work)
    line("Sahara / Mitsuba, the file", sahara, file_img)
    line("Sahara / Tungsten", sahara, ref)
    line("Mitsuba, the file / Tungsten", file_img, ref)
    line("Mitsuba, 64 bounces / Tungsten", mitsuba_of(mi, pbrt, 1024, w, h, work, depth=64), ref)

    # water-caustic: the box without its water (sppm against Mitsuba's path tracer, the light's
    # pixels masked), and the light seen through the waves: the spots of a window of the full
    # size, rendered by Sahara's camera paths alone (`distribution`), against Tungsten's.
    src = scene_file(bitterli, "water-caustic")
    text = open(src).read()
    folder = os.path.join(work, "water-caustic")
    os.makedirs(folder, exist_ok=True)
    os.symlink(os.path.join(os.path.dirname(src), "models"), os.path.join(folder, "models"))
    dry = os.path.join(folder, "dry.pbrt")
    open(dry, "w").write(text[:text.index('\nNamedMaterial "Water"')] + "\n")
    w = h = 128
    mask = test_mask("water-caustic")
    print(f"water-caustic without its water, {w} x {h}: Sahara sppm 32 iterations, Mitsuba 256 spp")
    sahara, _, _ = render(dry, w, h, 32, 1, os.path.join(work, "s.exr"))
    ratio, p50, p90, _ = measures(sahara, mitsuba_of(mi, dry, 256, w, h, work), mask)
    print(f"  Sahara / Mitsuba: ratio {ratio[0]:.4f} {ratio[1]:.4f} {ratio[2]:.4f}, "
          f"block error median {p50:.3f}, 90 % {p90:.3f}")
    window = os.path.join(folder, "window.pbrt")
    open(window, "w").write(text.replace(
        '"string filename" [ "water-caustic.exr" ]',
        '"string filename" [ "water-caustic.exr" ] "float cropwindow" [ 0.390625 0.4921875 '
        '0.1953125 0.2734375 ]'))
    out = os.path.join(work, "window.exr")
    subprocess.run([SAHARA, "render", window, "--integrator", "distribution", "--spp", "4096",
                    "--width", "1024", "--height", "1024", "--seed", "1", "-o", out],
                   check=True, capture_output=True)
    spots = read_exr(out)
    ref = read_exr(os.path.join(bitterli, "water-caustic", "pbrt", "TungstenRender.exr"))[200:280, 400:504]
    for name, img in [("Sahara, distribution, 4096 spp", spots), ("Tungsten", ref)]:
        bright = img.max(-1) > 20
        total = img[bright].sum(0)
        print(f"  the light through the waves, x 400-503, y 200-279 of 1024: {name}: "
              f"{bright.sum()} pixels over 20, their sum {total[0]:.0f} {total[1]:.0f} {total[2]:.0f}")


def variance(bitterli, work, seeds=16, spp=8):
    """Per-pixel variance of Sahara's bdpt against its path tracer at equal samples, over `seeds`
    renders of `spp` samples: veach-bidir (64 x 64, the file's maxdepth 7 for both) and the
    built-in Cornell box (32 x 32, independent samples). Multiple importance sampling should leave
    bdpt's variance at or below the path tracer's, whose strategies are among its own."""
    src = scene_file(bitterli, "veach-bidir")
    folder = os.path.join(work, "veach-bidir")
    os.makedirs(folder, exist_ok=True)
    os.symlink(os.path.join(os.path.dirname(src), "models"), os.path.join(folder, "models"))
    bdpt = os.path.join(folder, "bdpt.pbrt")
    shutil.copyfile(src, bdpt)
    path = os.path.join(folder, "path.pbrt")
    open(path, "w").write(open(src).read().replace('Integrator "bdpt"', 'Integrator "path"'))
    cases = [("veach-bidir, 64 x 64", [bdpt], [path], 64),
             ("Cornell box, 32 x 32", ["--integrator", "bdpt", "--sampler", "independent"],
              ["--integrator", "path", "--sampler", "independent"], 32)]
    for name, a_args, b_args, size in cases:
        stacks = []
        for args in (a_args, b_args):
            imgs = []
            for seed in range(1, seeds + 1):
                out = os.path.join(work, "v.exr")
                subprocess.run([SAHARA, "render", *args, "--width", str(size), "--height", str(size),
                                "--spp", str(spp), "--seed", str(seed), "-o", out],
                               check=True, capture_output=True)
                imgs.append(read_exr(out))
            stacks.append(np.stack(imgs))
        va, vb = (x.var(0, ddof=1).mean(-1) for x in stacks)
        b = size // 8
        blocks = va.reshape(8, b, 8, b).mean((1, 3)) / vb.reshape(8, b, 8, b).mean((1, 3))
        print(f"{name}, {seeds} renders of {spp} spp: bdpt / path, mean {stacks[0].mean():.4f} / "
              f"{stacks[1].mean():.4f}; per-pixel variance: mean {va.mean() / vb.mean():.3f}, "
              f"median of the pixels' ratios {np.median((va + 1e-12) / (vb + 1e-12)):.3f}, "
              f"8 x 8 grid of blocks {blocks.min():.2f} .. {blocks.max():.2f}")


def veach_mis_tungsten(pbrt, out, as_tungsten=True):
    """veach-mis as Tungsten rendered it, from its pbrt-v4 file: the same geometry, lights, camera
    and indices of refraction, with the three settings of Tungsten's scene the pbrt file lacks: the
    plates' microfacets are Beckmann and their reflectance is scaled by an albedo of 0.3, and light
    bounces once (direct light only: Mitsuba's `max_depth` 2). Written as a Mitsuba 3 scene (Mitsuba
    has all three) with the meshes as OBJ files beside it. With `as_tungsten` false, the pbrt file's
    own scene instead (GGX, no albedo, `maxdepth 3`), for Mitsuba to render."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from pbrt_mitsuba import get, matrix, parse
    folder = os.path.dirname(out)
    os.makedirs(folder, exist_ok=True)
    f3 = lambda v: ", ".join(f"{float(x):g}" for x in v)
    materials, world, shapes, lights, depth = {}, None, [], [], 5
    current, emission, transform = None, None, None
    width = height = fov = None
    for word, pos, params in parse(pbrt):
        if word == "Transform" and world is None:
            world = matrix(pos)
        elif word == "Film":
            width, height = int(get(params, "xresolution")[0]), int(get(params, "yresolution")[0])
        elif word == "Integrator":
            depth = int(get(params, "maxdepth", [depth])[0])
        elif word == "Camera":
            fov = float(get(params, "fov")[0])
        elif word == "MakeNamedMaterial":
            materials[pos[0]] = params
        elif word == "NamedMaterial":
            current = pos[0]
        elif word == "AreaLightSource":
            emission = get(params, "L")
        elif word == "AttributeEnd":
            emission = None
        elif word == "Transform":
            transform = matrix(pos)
        elif word == "Shape" and pos[0] == "sphere":
            centre = transform[:3, 3] if transform is not None else np.zeros(3)
            lights.append((centre, float(get(params, "radius")[0]), emission))
        elif word == "Shape" and pos[0] == "trianglemesh":
            shapes.append((current, get(params, "P"), [int(v) for v in get(params, "indices")]))
    # The camera: pbrt's Transform maps world to camera space, which looks along +z with +y up.
    to_world = np.linalg.inv(world)
    eye = to_world @ [0, 0, 0, 1]
    target = to_world @ [0, 0, 1, 1]
    up = to_world @ [0, 1, 0, 0]
    xml = [
        "<!-- veach-mis as Tungsten rendered it: written by scripts/bitterli_gallery.py from\n"
        "     scene-v4.pbrt (CC0, Benedikt Bitterli), with the plates' Beckmann microfacets and albedo\n"
        "     of 0.3 and the direct light only of Tungsten's scene, which the pbrt file lacks. -->"
        if as_tungsten else "<!-- veach-mis as its pbrt-v4 file has it -->",
        '<scene version="3.0.0">',
        f'    <integrator type="path"><integer name="max_depth" value="{2 if as_tungsten else depth + 1}"/>'
        '</integrator>',
        '    <sensor type="perspective">',
        f'        <float name="fov" value="{fov:g}"/><string name="fov_axis" value="smaller"/>',
        f'        <transform name="to_world"><lookat origin="{f3(eye[:3])}" target="{f3(target[:3])}" '
        f'up="{f3(up[:3])}"/></transform>',
        '        <sampler type="independent"><integer name="sample_count" value="64"/></sampler>',
        f'        <film type="hdrfilm"><integer name="width" value="{width}"/>'
        f'<integer name="height" value="{height}"/><rfilter type="tent"/></film>',
        "    </sensor>",
    ]
    for name, params in materials.items():
        kind = get(params, "type", [""])[0]
        if kind == "conductor":
            alpha = float(get(params, "uroughness")[0])
            assert get(params, "remaproughness") == [False] and get(params, "vroughness") == [alpha]
            distribution, albedo = ("beckmann", 0.3) if as_tungsten else ("ggx", 1.0)
            bsdf = (f'<bsdf type="roughconductor"><string name="distribution" value="{distribution}"/>'
                    f'<float name="alpha" value="{alpha:g}"/><rgb name="eta" value="{f3(get(params, "eta"))}"/>'
                    f'<rgb name="k" value="{f3(get(params, "k"))}"/>'
                    f'<rgb name="specular_reflectance" value="{f3([albedo] * 3)}"/></bsdf>')
        else:
            bsdf = f'<bsdf type="diffuse"><rgb name="reflectance" value="{f3(get(params, "reflectance"))}"/></bsdf>'
        xml.append(f'    <bsdf type="twosided" id="{name}">{bsdf}</bsdf>')
    for i, (material, points, indices) in enumerate(shapes):
        mesh = f"mesh{i}.obj"
        with open(os.path.join(folder, mesh), "w") as f:
            f.write("".join(f"v {points[j]:g} {points[j + 1]:g} {points[j + 2]:g}\n"
                            for j in range(0, len(points), 3)))
            f.write("".join(f"f {indices[j] + 1} {indices[j + 1] + 1} {indices[j + 2] + 1}\n"
                            for j in range(0, len(indices), 3)))
        xml.append(f'    <shape type="obj"><string name="filename" value="{mesh}"/>'
                   f'<boolean name="face_normals" value="true"/><ref id="{material}"/></shape>')
    for centre, radius, radiance in lights:
        xml.append(f'    <shape type="sphere"><point name="center" value="{f3(centre)}"/>'
                   f'<float name="radius" value="{radius:g}"/>'
                   f'<bsdf type="diffuse"><rgb name="reflectance" value="0, 0, 0"/></bsdf>'
                   f'<emitter type="area"><rgb name="radiance" value="{f3(radiance)}"/></emitter></shape>')
    xml.append("</scene>")
    open(out, "w").write("\n".join(xml) + "\n")


# Files a held case renders that are written from a scene's pbrt file, by name: (pbrt, out).
DERIVED = {"veach-mis-tungsten": veach_mis_tungsten}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bitterli", required=True, help="a checkout of the pbrt-v4 Bitterli scenes")
    ap.add_argument("--write", action="store_true", help="write the test's files and references")
    ap.add_argument("--seeds", type=int, default=0, help="measure the spread over seeds 1..N")
    ap.add_argument("--sheet", action="store_true", help="write the contact sheet")
    ap.add_argument("--survey", action="store_true", help="render every scene Sahara reads")
    ap.add_argument("--survey-spp", type=int, default=256)
    ap.add_argument("--causes", action="store_true", help="render the variants of CAUSES")
    ap.add_argument("--mitsuba", action="store_true", help="the checks with Mitsuba 3")
    ap.add_argument("--variance", action="store_true",
                    help="bdpt's per-pixel variance against the path tracer's")
    ap.add_argument("--keep-mb", type=float, default=10.0,
                    help="largest scene (its files, MB) kept in the repository (default 10)")
    ap.add_argument("--only", default="", help="comma-separated scene names")
    args = ap.parse_args()
    only = [s for s in args.only.split(",") if s]
    scenes = [s for s in GALLERY if not only or s in only]
    if not (args.write or args.seeds or args.sheet or args.survey or args.causes or args.mitsuba
            or args.variance):
        args.write, args.seeds, args.sheet = True, 8, True
    with tempfile.TemporaryDirectory() as work:
        if args.write:
            write(args.bitterli, scenes, args.keep_mb)
        if args.seeds:
            spread(args.bitterli, scenes, args.seeds, work)
        if args.sheet:
            sheet(args.bitterli, scenes, work)
        if args.survey:
            survey(args.bitterli, args.survey_spp, only, work)
        if args.causes:
            causes(args.bitterli, args.survey_spp, only, work)
        if args.mitsuba:
            mitsuba_checks(args.bitterli, work, only)
        if args.variance:
            variance(args.bitterli, work)


if __name__ == "__main__":
    main()
