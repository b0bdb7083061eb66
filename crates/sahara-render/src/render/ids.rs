//! The object and material passes: what the centre of each pixel shows.
//!
//! Ids cannot be averaged over a pixel's samples, so these passes are not
//! sums: each pixel gets the ids of the first surface the ray through its
//! centre meets (through the centre of the lens, at mid-shutter, passing
//! through alpha holes as the renderer does), 0 where it meets nothing.
//! They depend on the pixel alone, so a piece of the frame rendered on its
//! own has the whole frame's ids, whatever its samples.

use glam::Vec2;
use rayon::prelude::*;

use crate::film::window::PixelWindow;
use crate::integrator::through_hole;
use crate::world::World;

/// The ids of pixel centres of a window, rows top to bottom: the scene's
/// instance index + 1 and material index + 1 of the first surface seen (0:
/// none).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Ids {
    pub(crate) objects: Vec<u32>,
    pub(crate) materials: Vec<u32>,
}

/// The ids of the pixels of `window` of a `width x height` image.
pub(crate) fn pixel_centres(world: &World, window: &PixelWindow, width: u32, height: u32) -> Ids {
    let camera = &world.scene.camera;
    let inv = Vec2::new(1.0 / width as f32, 1.0 / height as f32);
    let rows: Vec<Vec<(u32, u32)>> = (window.y0..window.y1)
        .into_par_iter()
        .map(|y| {
            (window.x0..window.x1)
                .map(|x| {
                    let film = (Vec2::new(x as f32, y as f32) + 0.5) * inv;
                    let (mut ray, time) = camera.generate_ray(film, Vec2::splat(0.5), 0.5);
                    let mut holes = 0;
                    loop {
                        let Some(hit) = world.intersect(&ray, time) else {
                            return (0, 0);
                        };
                        if !through_hole(world, &mut ray, &hit, &mut holes) {
                            return (hit.instance + 1, hit.material + 1);
                        }
                    }
                })
                .collect()
        })
        .collect();
    let (objects, materials) = rows.into_iter().flatten().unzip();
    Ids { objects, materials }
}
