//! Scenes built in code, needing no files.

use glam::Vec3;

use crate::material::Material;
use crate::scene::camera::Camera;
use crate::scene::mesh::{Mesh, SceneMesh};
use crate::scene::shape::Shape;
use crate::scene::Scene;

/// The Cornell box: the Cornell Program of Computer Graphics' measured
/// geometry (millimetres, Y up), the usual reflectances, the ceiling light
/// emitting (17, 12, 4), seen from (278, 273, -800) looking +Z with a
/// vertical field of view of 39.3 degrees. The red wall (x = 550) appears
/// on the image's left, the green one (x = 0) on its right.
///
/// One piece: the scene's data (camera, materials, the measured quads of
/// walls, light and blocks) in the order the Cornell Program publishes it,
/// so that it reads against that table.
pub fn cornell_box() -> Scene {
    let camera = Camera::look_at(
        Vec3::new(278.0, 273.0, -800.0),
        Vec3::new(278.0, 273.0, 0.0),
        Vec3::Y,
        39.308,
        1.0,
    );
    let mut scene = Scene::new(camera);
    let white = scene.add_material(Material::diffuse(Vec3::new(0.725, 0.71, 0.68)));
    let red = scene.add_material(Material::diffuse(Vec3::new(0.63, 0.065, 0.05)));
    let green = scene.add_material(Material::diffuse(Vec3::new(0.14, 0.45, 0.091)));
    let light = scene.add_material(
        Material::diffuse(Vec3::splat(0.78)).with_emission(Vec3::new(17.0, 12.0, 4.0)),
    );
    // Quads (corners in order; the winding faces the box's interior or a
    // block's outside) and their materials.
    let v = Vec3::new;
    let quads: [([Vec3; 4], u32); 15] = [
        // Floor, ceiling, back wall, green (x = 0), red (x ~ 550).
        (
            [
                v(552.8, 0.0, 0.0),
                v(0.0, 0.0, 0.0),
                v(0.0, 0.0, 559.2),
                v(549.6, 0.0, 559.2),
            ],
            white,
        ),
        (
            [
                v(556.0, 548.8, 0.0),
                v(556.0, 548.8, 559.2),
                v(0.0, 548.8, 559.2),
                v(0.0, 548.8, 0.0),
            ],
            white,
        ),
        (
            [
                v(549.6, 0.0, 559.2),
                v(0.0, 0.0, 559.2),
                v(0.0, 548.8, 559.2),
                v(556.0, 548.8, 559.2),
            ],
            white,
        ),
        (
            [
                v(0.0, 0.0, 559.2),
                v(0.0, 0.0, 0.0),
                v(0.0, 548.8, 0.0),
                v(0.0, 548.8, 559.2),
            ],
            green,
        ),
        (
            [
                v(552.8, 0.0, 0.0),
                v(549.6, 0.0, 559.2),
                v(556.0, 548.8, 559.2),
                v(556.0, 548.8, 0.0),
            ],
            red,
        ),
        // Short block.
        (
            [
                v(130.0, 165.0, 65.0),
                v(82.0, 165.0, 225.0),
                v(240.0, 165.0, 272.0),
                v(290.0, 165.0, 114.0),
            ],
            white,
        ),
        (
            [
                v(290.0, 0.0, 114.0),
                v(290.0, 165.0, 114.0),
                v(240.0, 165.0, 272.0),
                v(240.0, 0.0, 272.0),
            ],
            white,
        ),
        (
            [
                v(130.0, 0.0, 65.0),
                v(130.0, 165.0, 65.0),
                v(290.0, 165.0, 114.0),
                v(290.0, 0.0, 114.0),
            ],
            white,
        ),
        (
            [
                v(82.0, 0.0, 225.0),
                v(82.0, 165.0, 225.0),
                v(130.0, 165.0, 65.0),
                v(130.0, 0.0, 65.0),
            ],
            white,
        ),
        (
            [
                v(240.0, 0.0, 272.0),
                v(240.0, 165.0, 272.0),
                v(82.0, 165.0, 225.0),
                v(82.0, 0.0, 225.0),
            ],
            white,
        ),
        // Tall block.
        (
            [
                v(423.0, 330.0, 247.0),
                v(265.0, 330.0, 296.0),
                v(314.0, 330.0, 456.0),
                v(472.0, 330.0, 406.0),
            ],
            white,
        ),
        (
            [
                v(423.0, 0.0, 247.0),
                v(423.0, 330.0, 247.0),
                v(472.0, 330.0, 406.0),
                v(472.0, 0.0, 406.0),
            ],
            white,
        ),
        (
            [
                v(472.0, 0.0, 406.0),
                v(472.0, 330.0, 406.0),
                v(314.0, 330.0, 456.0),
                v(314.0, 0.0, 456.0),
            ],
            white,
        ),
        (
            [
                v(314.0, 0.0, 456.0),
                v(314.0, 330.0, 456.0),
                v(265.0, 330.0, 296.0),
                v(265.0, 0.0, 296.0),
            ],
            white,
        ),
        (
            [
                v(265.0, 0.0, 296.0),
                v(265.0, 330.0, 296.0),
                v(423.0, 330.0, 247.0),
                v(423.0, 0.0, 247.0),
            ],
            white,
        ),
    ];
    let mut mesh = SceneMesh {
        mesh: Mesh::default(),
        material_ids: Some(Vec::new()),
        ..SceneMesh::default()
    };
    for (corners, mat) in quads {
        let base = mesh.mesh.positions.len() as u32;
        mesh.mesh.positions.extend(corners);
        mesh.mesh.indices.push([base, base + 1, base + 2]);
        mesh.mesh.indices.push([base, base + 2, base + 3]);
        let ids = mesh.material_ids.as_mut().expect("set above");
        ids.extend([mat, mat]);
    }
    let m = scene.add_mesh(mesh);
    scene.add_instance(crate::scene::instance::Instance::new(
        m,
        glam::Affine3A::IDENTITY,
        None,
    ));
    // The light, 0.1 mm below the ceiling, facing down.
    scene.add_shape(
        Shape::Quad {
            corner: v(343.0, 548.7, 227.0),
            edge_u: v(0.0, 0.0, 105.0),
            edge_v: v(-130.0, 0.0, 0.0),
        },
        light,
    );
    scene
}
