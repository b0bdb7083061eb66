//! `load_gltf` on arbitrary bytes (.gltf JSON or .glb): no panic; meshes with
//! indices in range, lights and cameras that convert, or a one-line error
//! naming the file.
//!
//! `sahara_readers::gltf` has no in-memory entry point, so each input is
//! written to a file in a fresh private folder (in /dev/shm when there is one)
//! and loaded from there; relative buffer and image URIs resolve inside that
//! empty folder.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use sahara_formats::{gltf_camera, gltf_light};
use sahara_fuzz::{check_error, check_mesh};
use sahara_readers::gltf::load_gltf;

fn input_path() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let shm = PathBuf::from("/dev/shm");
        let base = if shm.is_dir() {
            shm
        } else {
            std::env::temp_dir()
        };
        let dir = base.join(format!("sahara-fuzz-gltf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("cannot make the fuzz folder");
        dir.join("in.glb")
    })
}

fuzz_target!(|data: &[u8]| {
    let path = input_path();
    std::fs::write(path, data).expect("cannot write the fuzz input");
    let name = path.display().to_string();
    match load_gltf(path) {
        Ok(scene) => {
            for mesh in &scene.meshes {
                check_mesh(&mesh.mesh.positions, &mesh.mesh.indices);
            }
            for mesh in &scene.meshes {
                for &m in &mesh.material_ids {
                    assert!((m as usize) < scene.materials.len(), "material {m} missing");
                }
            }
            for instance in &scene.instances {
                assert!(instance.mesh < scene.meshes.len());
            }
            // Lights and cameras convert whatever the file's numbers.
            for light in &scene.lights {
                let _ = gltf_light(light, glam::Mat4::IDENTITY);
            }
            for camera in &scene.cameras {
                let _ = gltf_camera(camera);
            }
        }
        Err(e) => check_error(&e, &name),
    }
});
