use std::path::Path;
use sahara_formats::obj::parse_obj;
use sahara_formats::ply::parse_ply;
use sahara_formats::scene_file::parse_scene_file;
#[test]
fn probe() {
    let objs: &[&str] = &[
        "v nan 0 0\nv inf 1 0\nv 0 -inf 0\nf 1 2 3\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -99999999999999999999\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4294967297\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\nf 1 2 3\n",
        "v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/3\n",
        "f 1 2 3\n",
        "v 0 0\n",
    ];
    for t in objs { println!("OBJ {t:?} => {:?}", parse_obj(t.as_bytes(), "x.obj").map(|m| (m.positions, m.indices)).map_err(|e| e.to_string())); }
    let hdr = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    for f in ["3 0 1 99999999999999999999\n", "3 0 1 -99999999999999999999\n", "3 0 0 1\n", "3 0 1 2.0\n", "3 0 1 1e3\n", "255 0 1 2\n", "3 0 1\n"] {
        let t = format!("{hdr}{f}");
        println!("PLY {f:?} => {:?}", parse_ply(t.as_bytes(), "x.ply").map(|m| m.indices).map_err(|e| e.to_string()));
    }
    for h in ["ply\nformat ascii 1.0\nelement vertex 18446744073709551615\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
              "ply\nformat ascii 1.0\nelement vertex 18446744073709551616\nproperty float x\nend_header\n",
              "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1099511627776\nproperty list uchar int vertex_indices\nend_header\n"] {
        println!("PLYH => {:?}", parse_ply(h.as_bytes(), "x.ply").map(|m| m.indices).map_err(|e| e.to_string()));
    }
    let head = "[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n";
    for s in ["", "[camera]\n", "[[object]]\ntype = \"sphere\"\ncenter = [nan, 0, 0]\nradius = 1\n", "[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = inf\n",
              "[[object]]\ntype = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1\n", "[[object]]\ntype = \"quad\"\ncorner = [0, 0, 0]\nedge_u = [0, 0, 0]\nedge_v = [0, 0, 1]\n",
              "[[light]]\ntype = \"point\"\nposition = [0, 1, 0]\nintensity = [nan, 1, 1]\n", "[film]\nwidth = 0\n", "[sampler]\nspp = -1\n"] {
        let t = if s.is_empty() || s.starts_with("[camera]") { s.to_string() } else if s.starts_with("[film]") { format!("[camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\n{s}height = 4\n") } else { format!("{head}{s}") };
        println!("TOML {s:?} => {:?}", parse_scene_file(&t, "x.toml", Path::new("/nonexistent")).map(|_| ()).map_err(|e| e.to_string()));
    }
    let eye = "[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n";
    println!("TOML eye==target => {:?}", parse_scene_file(eye, "x.toml", Path::new("/nonexistent")).map(|_| ()).map_err(|e| e.to_string()));
    let eye = "[camera]\neye = [nan, 0, 0]\ntarget = [0, 0, 0]\n[film]\nwidth = 8\nheight = 4\n";
    println!("TOML eye nan => {:?}", parse_scene_file(eye, "x.toml", Path::new("/nonexistent")).map(|_| ()).map_err(|e| e.to_string()));
}
