"""Loading, rendering and writing: the command line's scenes, messages,
images and bytes; progress and Ctrl-C."""

import _thread
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import sahara
from conftest import ROOT

SCENES = ROOT / "scenes"


def metadata(integrator, spp, seed, w, h):
    """What the command line writes beside a complete image."""
    return {
        "sahara:integrator": integrator,
        "sahara:spp": str(spp),
        "sahara:seed": str(seed),
        "sahara:partial": "false",
        "sahara:finished_pixels": str(w * h),
    }


@pytest.mark.parametrize(
    "scene, args",
    [
        (None, ["--integrator", "distribution"]),
        (SCENES / "cornell_glossy_glass.toml", []),
        (SCENES / "cornell_box.xml", ["-D", "spp=3"]),
        # Another estimator keeps the file's path length (3 here, not 8).
        (SCENES / "cornell_box.xml", ["-D", "max_depth=3", "--integrator", "bdpt"]),
        (SCENES / "assets" / "bunny.ply", ["--integrator", "path"]),
    ],
)
def test_a_render_is_the_command_lines_bytes(tmp_path, sahara_bin, scene, args):
    w, h, spp, seed = 40, 30, 4, 5
    for ext in ["exr", "png"]:
        cli = tmp_path / f"cli.{ext}"
        cmd = [sahara_bin, "render"] + ([str(scene)] if scene else []) + args + [
            "--width", str(w), "--height", str(h), "--spp", str(spp), "--seed", str(seed), "-o", str(cli)]
        subprocess.run(cmd, check=True, capture_output=True)
        defines = dict(args[i + 1].split("=") for i, a in enumerate(args) if a == "-D")
        s = sahara.load(scene, **defines) if scene else sahara.cornell_box()
        fs = s.file_settings or {}
        integrator = args[args.index("--integrator") + 1] if "--integrator" in args else fs.get("integrator", "path")
        image = sahara.render(s, width=w, height=h, spp=spp, seed=seed, integrator=integrator if "--integrator" in args else None, progress=False)
        assert image.shape == (h, w, 3) and image.dtype == np.float32
        ours = tmp_path / f"py.{ext}"
        # The file's exposure and tone map apply to its PNG, as on the command line.
        sahara.write(ours, image, exposure=fs.get("exposure", 0.0), tonemap=fs.get("tonemap", "clamp"),
                     metadata=metadata(integrator, spp, seed, w, h))
        assert ours.read_bytes() == cli.read_bytes(), (scene, ext)


def test_the_same_seed_gives_the_same_image_and_another_seed_another():
    s = sahara.cornell_box()
    a = sahara.render(s, width=24, height=24, spp=2, seed=1, progress=False, threads=1)
    b = sahara.render(s, width=24, height=24, spp=2, seed=1, progress=False, threads=2)
    c = sahara.render(s, width=24, height=24, spp=2, seed=2, progress=False)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_either_structure_gives_the_same_image():
    s = sahara.cornell_box()
    kd = sahara.render(s, width=24, height=24, spp=2, accel="kd", progress=False)
    bvh = sahara.render(s, width=24, height=24, spp=2, accel="bvh", progress=False)
    np.testing.assert_array_equal(kd, bvh)


def test_the_path_loops_give_the_same_image_to_noise():
    s = sahara.cornell_box()
    images = {
        loop: sahara.render(s, width=24, height=24, spp=64, path_loop=loop, progress=False)
        for loop in ["scalar", "lanes", "lanes-no-refill", "auto"]
    }
    # The lanes round differently from the scalar loop, and auto takes the
    # lanes on the Cornell box; refilling changes no lane's arithmetic.
    np.testing.assert_array_equal(images["lanes"], images["auto"])
    np.testing.assert_array_equal(images["lanes"], images["lanes-no-refill"])
    scalar, lanes = images["scalar"].mean(), images["lanes"].mean()
    assert abs(scalar - lanes) < 0.02 * scalar


def test_file_settings_hold_unless_given():
    s = sahara.load(SCENES / "cornell_box.xml", spp=3)
    assert s.file_settings["spp"] == 3
    assert sahara.load(SCENES / "cornell_box.xml", defines={"spp": 5}).file_settings["spp"] == 5
    fs = s.file_settings
    image = sahara.render(s, width=16, height=12, progress=False)
    assert image.shape == (12, 16, 3)
    assert s.name == "cornell_box" and fs["integrator"]


def test_render_passes_come_as_arrays():
    image, passes = sahara.render(sahara.cornell_box(), width=20, height=10, spp=2, progress=False,
                                  aovs=["albedo", "normal", "depth", "uv", "object"])
    assert set(passes) == {"albedo", "normal", "depth", "uv", "object"}
    assert passes["albedo"].shape == (10, 20, 3) and passes["depth"].shape == (10, 20)
    assert passes["uv"].shape == (10, 20, 2) and passes["object"].dtype == np.uint32
    assert (passes["depth"] > 0).mean() > 0.4 and passes["object"].max() >= 1
    with pytest.raises(ValueError, match="aovs: the bdpt integrator cannot make render passes"):
        sahara.render(sahara.cornell_box(), integrator="bdpt", aovs=["depth"], progress=False)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"integrator": "whitted"}, "unknown integrator 'whitted'"),
        ({"aovs": ["colour"]}, "unknown render pass 'colour'"),
        ({"spp": 0}, "spp: 0 is not in 1..=1048576"),
        ({"width": 0}, r"width: 0 is not in 1..=65536"),
        ({"noise_threshold": -1}, r"noise_threshold: must be a positive number"),
        ({"time_limit": 0}, "time_limit: must be a positive number of seconds"),
        ({"part": (2, 2)}, r"part: '2, 2' is not a part I/N"),
        ({"min_spp": 4}, r"min_spp: needs a noise threshold"),
        ({"split": "samples"}, r'split="samples": applies to a part'),
        ({"aovs": ["depth"], "output": "x.png"}, r"aovs: render passes are written as layers of an EXR"),
        ({"builder": "bvh"}, "builder: unknown builder 'bvh'"),
        ({"accel": "octree"}, "accel: unknown structure 'octree'"),
        ({"path_loop": "wide"}, "path_loop: unknown path loop 'wide'"),
    ],
)
def test_bad_settings_are_value_errors(kwargs, message):
    with pytest.raises(ValueError, match=message):
        sahara.render(sahara.cornell_box(), progress=False, **kwargs)


def test_settings_of_the_wrong_kind_are_type_errors():
    for kwargs, message in [
        ({"spp": 2.5}, "spp: expected a whole number, got a number"),
        ({"spp": "16"}, "spp: expected a whole number, got str"),
        ({"denoise": 1}, "denoise: expected True or False"),
        ({"aovs": 3}, "aovs: expected a name or a list of names, got a whole number"),
        ({"sppp": 4}, "unexpected keyword argument 'sppp'"),
    ]:
        with pytest.raises(TypeError, match=message):
            sahara.render(sahara.cornell_box(), progress=False, **kwargs)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"spp": -1}, r"spp: -1 is not in 1..=1048576"),
        ({"spp": 2**40}, r"spp: 1099511627776 is not in 1..=1048576"),
        ({"width": -5}, r"width: -5 is not in 1..=65536"),
        ({"height": 10**6}, r"height: 1000000 is not in 1..=65536"),
        ({"pass_spp": -2}, r"pass_spp: -2 is not in 1..=1048576"),
        ({"seed": -1}, r"seed: -1 is not in 0..="),
        ({"threads": -1}, r"threads: -1 is not in 0..=1024"),
    ],
)
def test_arguments_out_of_range_name_the_argument(kwargs, message):
    # Not the conversion's OverflowError: the exception a Python user
    # expects, naming the argument.
    with pytest.raises(ValueError, match=message):
        sahara.render(sahara.cornell_box(), progress=False, **kwargs)


def test_numpy_integers_are_whole_numbers_and_one_pass_name_is_a_name():
    image, passes = sahara.render(sahara.cornell_box(), width=np.int64(8), height=np.uint16(6),
                                  spp=np.int32(1), aovs="albedo", progress=False)
    assert image.shape == (6, 8, 3)
    assert list(passes) == ["albedo"]


def test_writing_to_a_folder_says_it_is_a_folder(tmp_path):
    with pytest.raises(IsADirectoryError, match="is a folder"):
        sahara.write(tmp_path, np.zeros((2, 2, 3), dtype=np.float32))


def test_uint8_images_are_srgb_codes_as_pil_reads_them(tmp_path):
    # Every 8-bit code, written as a PNG, comes back as the same code: the
    # codes are sRGB-encoded (as PIL and imageio give them), not linear
    # values that would saturate.
    codes = np.arange(256, dtype=np.uint8).reshape(16, 16, 1).repeat(3, axis=2)
    out = tmp_path / "codes.png"
    sahara.write(out, codes)
    import zlib

    data = out.read_bytes()
    # The PNG's pixels, from its IDAT chunks (filtered rows of RGB).
    idat, at = b"", 8
    while at < len(data):
        n = int.from_bytes(data[at:at + 4], "big")
        kind = data[at + 4:at + 8]
        if kind == b"IDAT":
            idat += data[at + 8:at + 8 + n]
        at += 12 + n
    rows = zlib.decompress(idat)
    width, stride = 16, 16 * 3
    pixels, prev = [], bytearray(stride)
    for y in range(16):
        f, raw = rows[y * (stride + 1)], bytearray(rows[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = raw[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
            if f == 1:
                raw[i] = (raw[i] + a) & 255
            elif f == 2:
                raw[i] = (raw[i] + b) & 255
            elif f == 3:
                raw[i] = (raw[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                raw[i] = (raw[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        pixels.append(bytes(raw))
        prev = raw
    got = np.frombuffer(b"".join(pixels), dtype=np.uint8).reshape(16, width, 3)
    assert (got == codes).all()
    # The same image as linear floats (what the codes mean) writes the
    # same bytes.
    c = codes.astype(np.float64) / 255
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)
    sahara.write(tmp_path / "linear.png", linear)
    assert (tmp_path / "linear.png").read_bytes() == data
    # Other integer types are refused.
    with pytest.raises(TypeError, match="int32 pixels cannot be written"):
        sahara.write(tmp_path / "i.png", codes.astype(np.int32))


def test_nan_pixels_are_counted_in_a_warning(tmp_path):
    image = np.full((4, 4, 3), 0.5, dtype=np.float32)
    image[0, 0, :] = np.nan
    image[2, 1, 1] = np.nan
    with pytest.warns(RuntimeWarning, match="image: 4 of 48 values are NaN; they are written as black"):
        sahara.write(tmp_path / "nan.png", image)
    with pytest.warns(RuntimeWarning, match="written as NaN"):
        sahara.write(tmp_path / "nan.exr", image)


def test_a_render_beyond_the_machines_memory_is_a_memory_error():
    with pytest.raises(MemoryError, match=r"this render needs about 384.0 GiB \(32 triangles, a 65536x65536 film\)"):
        sahara.render(sahara.cornell_box(), width=65536, height=65536, spp=1, progress=False)


def test_files_at_fault_are_named_with_the_line(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.toml: not found"):
        sahara.load(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[camera]\nfov = 40\n")
    with pytest.raises(sahara.FormatError) as e:
        sahara.load(bad)
    assert str(e.value).startswith(f"{bad}: line 2: ")
    stl = tmp_path / "mesh.stl"
    stl.write_text("solid x\n")
    with pytest.raises(sahara.FormatError, match=r"mesh.stl: cannot render .stl files"):
        sahara.load(stl)
    obj = tmp_path / "m.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    # A keyword load() does not take is a TypeError, as Python says one
    # (only a Mitsuba scene takes parameters as keywords).
    with pytest.raises(TypeError, match="load\\(\\) got an unexpected keyword argument 'camra'"):
        sahara.load(obj, camra="x")
    with pytest.raises(sahara.FormatError, match=r"out.bmp"):
        sahara.write(tmp_path / "out.bmp", np.zeros((2, 2, 3)))
    with pytest.raises(ValueError, match="image: expected an array of shape"):
        sahara.write(tmp_path / "out.png", np.zeros((2, 2)))


@pytest.mark.parametrize(
    "name, text, message",
    [
        ("bad.pbrt", 'WorldBegin\nShape "trianglemesh" "point3 P" [0 0 0 1 0 0]\n', "line 2: column 1: trianglemesh needs"),
        ("bad.xml", '<scene version="3.0.0">\n  <shape type="obj">\n  </shape>\n<scene>\n', "line 4: column 8: the file ends inside an element that is not closed"),
        ("bad.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nend_header\n\x01",
         "line 3: element vertex has no property 'y'"),
        ("bad.gltf", '{"asset": {"version": "2.0"}, "meshes": [', "line 1: column 41: invalid glTF JSON"),
        ("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n", "line 3: face refers to a vertex that does not exist"),
    ],
)
def test_every_format_names_the_file_and_line_at_fault(tmp_path, name, text, message):
    path = tmp_path / name
    path.write_bytes(text.encode())
    with pytest.raises(sahara.FormatError) as e:
        sahara.load(path)
    assert str(e.value).startswith(f"{path}: ") and message in str(e.value)


def test_the_progress_bar_writes_plain_lines_where_stderr_is_not_a_terminal():
    # A script's stderr is a pipe here: no carriage returns, and the last
    # line says the render finished and ends with a newline.
    script = (
        "import sahara\n"
        "sahara.render(sahara.cornell_box(), width=32, height=32, spp=2, pass_spp=1)\n"
    )
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    err = p.stderr
    if "it/s]" in err or "tile/s]" in err:
        pytest.skip("tqdm is installed: its bar is drawn instead")
    assert "\r" not in err, repr(err)
    assert err.endswith("\n"), repr(err)
    lines = err.splitlines()
    assert lines and all(line.startswith("rendering ") and "% done" in line for line in lines), lines
    assert lines[-1].startswith("rendering ") and "100% done, finished" in lines[-1], lines


def test_progress_is_reported_to_the_end():
    seen = []
    sahara.render(sahara.cornell_box(), width=64, height=64, spp=8, pass_spp=2,
                  progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1][0] == seen[-1][1] > 0
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))


def test_ctrl_c_stops_the_render_with_keyboard_interrupt():
    scene = sahara.cornell_box()
    before = threading.active_count()
    timer = threading.Timer(0.5, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sahara.render(scene, width=256, height=256, spp=100000, progress=False)
    stopped = time.monotonic() - start
    timer.join()
    assert stopped < 10, f"took {stopped:.1f} s to stop"
    assert threading.active_count() == before
    # The threads are free: the next render runs.
    assert sahara.render(scene, width=8, height=8, spp=1, progress=False).shape == (8, 8, 3)


def test_an_exception_in_the_progress_function_stops_the_render():
    def fail(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        sahara.render(sahara.cornell_box(), width=128, height=128, spp=100000, progress=fail)


def test_a_setting_that_cannot_do_what_it_asks_is_a_warning():
    with pytest.warns(UserWarning, match="adaptive: every pixel takes all 4 samples"):
        sahara.render(sahara.cornell_box(), width=8, height=8, spp=4, noise_threshold=0.1,
                      progress=False)
