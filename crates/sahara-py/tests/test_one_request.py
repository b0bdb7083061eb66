"""One front door: `sahara render` and `sahara.render` make a render from
one request, so the same scene and settings give the same file, byte for
byte: denoised, cropped by the scene file, bounded by a time limit,
sampled adaptively, with render passes, and as a farm's parts (which
`sahara merge` adds up to the frame rendered whole). A render larger than
memory is refused by both with the same message."""

import os
import re
import struct
import subprocess
import zlib

import pytest

import sahara
from conftest import ROOT

SCENES = ROOT / "scenes"

SIZE = ["--width", "40", "--height", "30"]


def cli(sahara_bin, args, check=True):
    """Runs `sahara render ARGS`; its stderr."""
    r = subprocess.run([sahara_bin, "render"] + args, capture_output=True, text=True,
                       env=dict(os.environ, SAHARA_PROGRESS_EVERY="1000"))
    if check and r.returncode != 0:
        raise AssertionError(f"sahara render {' '.join(args)}:\n{r.stderr}")
    return r


def keywords(args):
    """The keyword arguments of `sahara.render` for command-line options:
    the same names, `--aov` as `aovs`; a switch is True; values as the
    command line's text (`as_python` makes the numbers numbers, which
    Python requires)."""
    out, i = {}, 0
    while i < len(args):
        name = args[i][2:].replace("-", "_")
        if name == "denoise":
            out[name], i = True, i + 1
            continue
        value = args[i + 1]
        out["aovs" if name == "aov" else name] = value.split(",") if name == "aov" else value
        i += 2
    return out


def as_python(args):
    """The same settings as Python values where Python has its own: numbers
    (a number given as a str is a TypeError) and tuples, to hold the
    translation of each as well."""
    kw = keywords(args)
    for k in ("spp", "pass_spp", "width", "height", "seed", "min_spp"):
        if k in kw:
            kw[k] = int(kw[k])
    for k in ("noise_threshold", "time_limit", "exposure"):
        if k in kw:
            kw[k] = float(kw[k])
    if "part" in kw:
        kw["part"] = tuple(int(x) for x in kw["part"].split("/"))
    if "crop" in kw:
        kw["crop"] = [float(x) for x in kw["crop"].split(",")]
    if "samples" in kw:
        kw["samples"] = tuple(int(x) for x in kw["samples"].split(".."))
    return kw


def png_text(path):
    """A PNG's text chunks."""
    data, out, at = path.read_bytes(), {}, 8
    while at < len(data):
        n, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + n]
        if kind == b"tEXt":
            k, _, v = body.partition(b"\0")
            out[k.decode()] = v.decode()
        elif kind == b"zTXt":
            k, _, rest = body.partition(b"\0")
            out[k.decode()] = zlib.decompress(rest[1:]).decode()
        at += 12 + n
    return out


def denoiser_or_skip():
    try:
        sahara.render(sahara.cornell_box(), width=4, height=4, spp=1, denoise=True, progress=False)
    except RuntimeError as e:
        if "SAHARA_REQUIRE_OIDN" in os.environ:
            raise
        pytest.skip(f"Open Image Denoise is not installed: {e}")


def crop_scene(tmp_path):
    """A pbrt scene whose film keeps a crop window of its image."""
    path = tmp_path / "crop.pbrt"
    path.write_text(
        'Film "rgb" "integer xresolution" 40 "integer yresolution" 30 '
        '"float cropwindow" [0.2 0.7 0.1 0.6]\n'
        'Sampler "zsobol" "integer pixelsamples" 4\n'
        'LookAt 0 0 5  0 0 0  0 1 0\nCamera "perspective" "float fov" 40\nWorldBegin\n'
        'LightSource "point" "rgb I" [20 20 20] "point3 from" [2 3 4]\n'
        'Material "diffuse" "rgb reflectance" [0.6 0.5 0.4]\nShape "sphere" "float radius" 1\n'
        'AttributeBegin\nTranslate 0 -1 0\nShape "trianglemesh" "integer indices" [0 1 2 2 1 3] '
        '"point3 P" [-4 0 -4 4 0 -4 -4 0 4 4 0 4]\nAttributeEnd\n')
    return path


CASES = {
    "plain": (None, ["--integrator", "distribution", "--spp", "4"]),
    "file settings and passes": (SCENES / "cornell_glossy_glass.toml",
                                 ["--spp", "2", "--aov", "depth,albedo,object"]),
    "adaptive": (None, ["--spp", "16", "--pass-spp", "4", "--noise-threshold", "0.05",
                        "--min-spp", "4"]),
    "time limit with a count": (None, ["--spp", "3", "--time-limit", "600"]),
    "filter, sampler, seed, builder": (None, ["--filter", "mitchell", "--sampler", "stratified",
                                              "--seed", "9", "--builder", "binned16", "--spp", "2"]),
    "png look": (SCENES / "cornell_box.xml", ["--spp", "2", "--exposure", "1.5",
                                              "--tonemap", "filmic"]),
}


@pytest.mark.parametrize(
    "case, ext",
    # Render passes are layers of an EXR.
    [(c, e) for c in CASES for e in ["exr", "png"] if not ("--aov" in CASES[c][1] and e == "png")],
)
def test_the_same_settings_write_the_same_file(tmp_path, sahara_bin, case, ext):
    scene, args = CASES[case]
    ours, theirs = tmp_path / f"py.{ext}", tmp_path / f"cli.{ext}"
    cli(sahara_bin, ([str(scene)] if scene else []) + args + SIZE + ["-o", str(theirs)])
    s = sahara.load(scene) if scene else sahara.cornell_box()
    sahara.render(s, progress=False, output=ours, **as_python(args + SIZE))
    assert ours.read_bytes() == theirs.read_bytes(), case


def test_the_same_denoised_file(tmp_path, sahara_bin):
    denoiser_or_skip()
    for ext in ["exr", "png"]:
        ours, theirs = tmp_path / f"py.{ext}", tmp_path / f"cli.{ext}"
        args = ["--spp", "4", "--denoise"] + SIZE
        r = cli(sahara_bin, args + ["-o", str(theirs)])
        assert "denoise: box filter" in r.stderr
        image = sahara.render(sahara.cornell_box(), progress=False, output=ours, **as_python(args))
        assert ours.read_bytes() == theirs.read_bytes(), ext
        assert image.shape == (30, 40, 3)


def test_the_same_crop_of_a_scene_files_film(tmp_path, sahara_bin):
    scene = crop_scene(tmp_path)
    ours, theirs = tmp_path / "py.exr", tmp_path / "cli.exr"
    r = cli(sahara_bin, [str(scene), "-o", str(theirs)])
    assert "crop window of the scene file: pixels" in r.stderr
    image = sahara.render(sahara.load(scene), progress=False, output=ours)
    assert ours.read_bytes() == theirs.read_bytes()
    # pbrt-v4's pixel bounds: ceil(0.2 * 40)..ceil(0.7 * 40), ceil(0.1 * 30)..ceil(0.6 * 30).
    assert image.shape == (18 - 3, 28 - 8, 3)


@pytest.mark.parametrize(
    "pieces",
    [
        [["--part", "0/2"], ["--part", "1/2"]],
        [["--part", "0/3", "--split", "samples"], ["--part", "1/3", "--split", "samples"],
         ["--part", "2/3", "--split", "samples"]],
        [["--crop", "0,0.5,0,1"], ["--crop", "0.5,1,0,1"]],
        [["--samples", "0..2"], ["--samples", "2..6"]],
    ],
    ids=["tiles", "samples", "crop windows", "sample ranges"],
)
def test_parts_from_either_front_end_merge_to_the_frame_rendered_whole(tmp_path, sahara_bin, pieces):
    settings = ["--spp", "6", "--pass-spp", "2", "--seed", "3", "--aov", "albedo"] + SIZE
    whole = tmp_path / "whole.exr"
    cli(sahara_bin, settings + ["-o", str(whole)])
    for first in ["cli", "py"]:
        parts = []
        for k, piece in enumerate(pieces):
            path = tmp_path / f"{first}-{k}.exr"
            if (k % 2 == 0) == (first == "cli"):
                cli(sahara_bin, settings + piece + ["-o", str(path)])
            else:
                sahara.render(sahara.cornell_box(), progress=False, output=path,
                              **as_python(settings + piece))
            parts.append(str(path))
        merged = tmp_path / f"merged-{first}.exr"
        r = subprocess.run([sahara_bin, "merge", *parts, "-o", str(merged)], capture_output=True,
                           text=True)
        assert r.returncode == 0, r.stderr
        assert merged.read_bytes() == whole.read_bytes(), first


def test_a_time_limit_alone_lifts_the_sample_count_in_both(tmp_path, sahara_bin):
    """With a time limit and no count, both render passes until the time
    is up, whatever the file's count; the image is then the image of the
    passes done."""
    scene = tmp_path / "two.toml"
    scene.write_text(
        "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n[[object]]\ntype = \"sphere\"\n"
        "center = [0, 0, 0]\nradius = 1\n[[light]]\ntype = \"point\"\nposition = [0, 4, 2]\n"
        "intensity = [20, 20, 20]\n[sampler]\nspp = 2\n[film]\nwidth = 40\nheight = 30\n")
    base = ["--pass-spp", "2"]
    ours, theirs = tmp_path / "py.png", tmp_path / "cli.png"
    sahara.render(sahara.load(scene), progress=False, output=ours, time_limit=2.0,
                  **as_python(base))
    cli(sahara_bin, [str(scene), "--time-limit", "2", "-o", str(theirs)] + base)
    for done in [ours, theirs]:
        spp = int(png_text(done)["sahara:spp"])
        assert spp % 2 == 0 and spp > 2, (done.name, spp)
        # The same image as a count of those samples, through the other door.
        other = tmp_path / f"again-{done.name}"
        if done == ours:
            cli(sahara_bin, [str(scene), "--spp", str(spp), "-o", str(other)] + base)
        else:
            sahara.render(sahara.load(scene), progress=False, output=other, spp=spp,
                          **as_python(base))
        assert other.read_bytes() == done.read_bytes(), done.name


def test_a_render_larger_than_memory_is_refused_by_both_with_the_same_message(tmp_path, sahara_bin):
    big = ["--width", "65536", "--height", "65536", "--spp", "1"]
    out = tmp_path / "huge.png"
    r = cli(sahara_bin, big + ["-o", str(out)], check=False)
    assert r.returncode == 1 and not out.exists()
    with pytest.raises(MemoryError) as e:
        sahara.render(sahara.cornell_box(), progress=False, output=out, **as_python(big))
    assert not out.exists()
    # The memory available moves between the two calls.
    said = [re.sub(r"only [0-9.]+ GiB", "only N GiB", m) for m in
            (r.stderr.strip().removeprefix("error: "), str(e.value))]
    assert said[0] == said[1], said
    assert said[0].startswith("this render needs about 384.0 GiB"), said[0]


def test_a_refused_setting_is_named_by_each_front_end_its_way(tmp_path, sahara_bin):
    out = str(tmp_path / "x.exr")
    r = cli(sahara_bin, ["--integrator", "sppm", "--noise-threshold", "0.05", "-o", out], check=False)
    assert "--noise-threshold: the sppm integrator cannot sample adaptively" in r.stderr
    with pytest.raises(ValueError, match="^noise_threshold: the sppm integrator cannot sample adaptively"):
        sahara.render(sahara.cornell_box(), integrator="sppm", noise_threshold=0.05, progress=False)
