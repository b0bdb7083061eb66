//! OBJ with MTL: materials, per-triangle ids, per-vertex normals/uvs, warnings.

use std::fs;

use glam::{Vec2, Vec3};
use sahara_readers::mtl::MtlMaterial;
use sahara_readers::obj::{load_obj, load_obj_with_materials};

use crate::common::{corners, scenes_dir, skip_note, TempDir};

#[test]
fn cornell_box_materials_and_ids() {
    let path = scenes_dir().join("cornell_box/cornell_box.obj");
    if !path.exists() {
        skip_note(&format!(
            "the shared Cornell box's materials ({} not found; set SAHARA_SCENES)",
            path.display()
        ));
        return;
    }
    let scene = load_obj_with_materials(&path).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["white", "red", "green", "light"]);
    let light = &scene.materials[3];
    assert_eq!(light.ke, [17.0, 12.0, 4.0]);
    assert_eq!(light.kd, [0.78, 0.78, 0.78]);
    assert_eq!(light.illum, 1);
    assert_eq!(scene.materials[1].kd, [0.63, 0.065, 0.05]);
    assert_eq!(scene.materials[0].ke, [0.0; 3]);
    assert_eq!(scene.materials[0].map_kd, None);

    // floor, ceiling, back wall (white), green wall, red wall, two blocks of
    // 10 triangles (white), light.
    let mut expected = vec![0u32; 6];
    expected.extend([2, 2, 1, 1]);
    expected.extend([0; 20]);
    expected.extend([3, 3]);
    assert_eq!(scene.material_ids, expected);

    // Same triangles as the plain loader; no normals or uvs in this file.
    let plain = load_obj(&path).unwrap();
    assert_eq!(corners(&scene.mesh), corners(&plain));
    assert_eq!(scene.normals, None);
    assert_eq!(scene.uvs, None);
}

#[test]
fn sponza_textures_resolve_next_to_the_mtl() {
    let path = scenes_dir().join("sponza/sponza.obj");
    if !path.exists() {
        skip_note(&format!(
            "the shared Sponza's textures ({} not found; set SAHARA_SCENES)",
            path.display()
        ));
        return;
    }
    let scene = load_obj_with_materials(&path).unwrap();
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.mesh.triangle_count(), 66_454);
    assert_eq!(scene.material_ids.len(), 66_454);
    assert!(scene
        .material_ids
        .iter()
        .all(|&i| (i as usize) < scene.materials.len()));
    let floor = scene.materials.iter().find(|m| m.name == "floor").unwrap();
    assert_eq!(
        floor
            .map_kd
            .as_deref()
            .map(fs::canonicalize)
            .unwrap()
            .unwrap(),
        fs::canonicalize(scenes_dir().join("sponza/textures/kamen.jpg")).unwrap()
    );
    let textured = scene
        .materials
        .iter()
        .filter(|m| m.map_kd.is_some())
        .count();
    assert!(textured >= 10, "{textured} textured materials");
    for m in &scene.materials {
        if let Some(t) = &m.map_kd {
            assert!(t.is_file(), "{}", t.display());
        }
    }
    let uvs = scene.uvs.as_ref().expect("sponza has texture coordinates");
    let normals = scene.normals.as_ref().expect("sponza has normals");
    assert_eq!(uvs.len(), scene.mesh.positions.len());
    assert_eq!(normals.len(), scene.mesh.positions.len());
}

#[test]
fn missing_library_and_unknown_material_are_warnings_with_the_default_material() {
    let dir = TempDir::new("mtl-missing");
    let obj = dir.write(
        "m.obj",
        "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl ghost\nf 1 2 3\nf 3 2 1\n",
    );
    let scene = load_obj_with_materials(&obj).unwrap();
    assert_eq!(scene.materials, vec![MtlMaterial::default_material()]);
    assert_eq!(scene.material_ids, vec![0, 0]);
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0].contains("m.obj") && scene.warnings[0].contains("nowhere.mtl"),
        "{}",
        scene.warnings[0]
    );
    assert!(
        scene.warnings[1].contains("line 5") && scene.warnings[1].contains("ghost"),
        "{}",
        scene.warnings[1]
    );
    assert_eq!(scene.materials[0].kd, [0.8, 0.8, 0.8]);
}

#[test]
fn textures_resolve_relative_to_the_mtl_file_and_missing_ones_warn() {
    let dir = TempDir::new("mtl-tex");
    fs::create_dir(dir.0.join("mat")).unwrap();
    dir.write("mat/wood.png", b"not really a png, only has to exist");
    dir.write(
        "mat/lib.mtl",
        "newmtl wood\nKd 0.5 0.4 0.3\nKs 0.1 0.2 0.3\nNs 50\nNi 1.5\nd 0.75\nillum 7\nmap_Kd -s 1 1 1 wood.png\n\
         newmtl stone\nmap_Kd stone.png\n\
         newmtl plain\n",
    );
    let obj = dir.write(
        "m.obj",
        "mtllib mat/lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
         usemtl stone\nf 1 2 3\nusemtl wood\nf 2 4 3\nf 1 2 4\nusemtl plain\nf 1 2 3\nf 1 3 4\n",
    );
    let scene = load_obj_with_materials(&obj).unwrap();
    let wood = &scene.materials[0];
    assert_eq!(wood.name, "wood");
    assert_eq!(wood.kd, [0.5, 0.4, 0.3]);
    assert_eq!(wood.ks, [0.1, 0.2, 0.3]);
    assert_eq!((wood.ns, wood.ni, wood.d, wood.illum), (50.0, 1.5, 0.75, 7));
    assert_eq!(wood.map_kd, Some(dir.0.join("mat").join("wood.png")));
    let stone = &scene.materials[1];
    assert_eq!(stone.map_kd, None);
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    assert!(
        w.contains("lib.mtl") && w.contains("stone.png") && w.contains("stone"),
        "{w}"
    );
    // Materials left unset take the defaults.
    let plain = &scene.materials[2];
    let expected = MtlMaterial {
        name: "plain".into(),
        ..MtlMaterial::default_material()
    };
    assert_eq!(plain, &expected);
    assert_eq!(scene.material_ids, vec![1, 0, 0, 2, 2]);
    assert_eq!(scene.materials.len(), 3, "no default needed");
}

#[test]
fn a_malformed_mtl_is_an_error_naming_it() {
    let dir = TempDir::new("mtl-bad");
    dir.write("bad.mtl", "newmtl x\nKd 0.5 zero 1\n");
    let obj = dir.write(
        "m.obj",
        "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let err = load_obj_with_materials(&obj).unwrap_err().to_string();
    assert!(err.contains("bad.mtl") && !err.contains('\n'), "{err}");
}

#[test]
fn normals_and_uvs_are_per_vertex_and_split_where_corners_differ() {
    // Two triangles share the edge 2-3, but vertex 2 has different uvs in each.
    let text = "\
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
vt 0 0
vt 1 0
vt 0 1
vt 0.5 0.5
vn 0 0 1
vn 0 0 -1
f 1/1/1 2/2/1 3/3/1
f 2/4/2 4/2/2 3/3/2
";
    let dir = TempDir::new("obj-attr");
    let obj = dir.write("a.obj", text);
    let scene = load_obj_with_materials(&obj).unwrap();
    // 6 distinct (v, vt, vn) corners: the second face shares no triple with the first.
    assert_eq!(scene.mesh.positions.len(), 6);
    let normals = scene.normals.as_ref().unwrap();
    let uvs = scene.uvs.as_ref().unwrap();
    let corner = |t: usize, k: usize| {
        let v = scene.mesh.indices[t][k] as usize;
        (scene.mesh.positions[v], uvs[v], normals[v])
    };
    assert_eq!(
        corner(0, 1),
        (Vec3::new(1., 0., 0.), Vec2::new(1., 0.), Vec3::Z)
    );
    assert_eq!(
        corner(1, 0),
        (Vec3::new(1., 0., 0.), Vec2::new(0.5, 0.5), Vec3::NEG_Z)
    );
    assert_eq!(
        corner(1, 1),
        (Vec3::new(1., 1., 0.), Vec2::new(1., 0.), Vec3::NEG_Z)
    );
    assert_eq!(scene.material_ids, vec![0, 0]);
    assert_eq!(scene.materials[0].name, "default");

    // A corner triple used twice is one vertex.
    let dir2 = TempDir::new("obj-attr2");
    let obj = dir2.write(
        "b.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nf 1/1 2/1 3/1 4/1\n",
    );
    let scene = load_obj_with_materials(&obj).unwrap();
    assert_eq!(scene.mesh.positions.len(), 4);
    assert_eq!(scene.mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(scene.normals, None);
    assert_eq!(scene.uvs, Some(vec![Vec2::ZERO; 4]));
}
