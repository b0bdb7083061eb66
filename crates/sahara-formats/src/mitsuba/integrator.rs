//! Mitsuba's `<integrator>` as Sahara's.
//!
//! Depth: Mitsuba's `max_depth` counts path segments from the camera (1:
//! emitters seen directly, 2: direct light, -1: no limit); Sahara's counts
//! scattering events (1: direct light). So Sahara's is Mitsuba's minus
//! one. Both start Russian roulette once `rr_depth` bounces are done
//! (`rr_depth` carries over as it is).
//!
//! | Mitsuba | Sahara |
//! |---|---|
//! | `path` (`max_depth`, `rr_depth`) | path tracer |
//! | `direct` | path tracer of depth 1: direct light with MIS |
//! | `volpath`, `volpathmis` | path tracer (the volumetric one in a scene with media) |
//! | `prb`, `prb_basic`, `prbvolpath`, `ptracer` | path tracer (warned) |
//! | `depth` | depth |
//! | `aov` | its nested integrator (warned: the image only) |
//! | `hide_emitters` | not supported (warned) |

use sahara_readers::FormatError;
use sahara_render::Integrator;

use super::builder::Builder;
use super::properties::Object;
use super::xml::Node;

/// Sahara's deepest path.
const MAX_DEPTH: u32 = 1 << 16;

/// Path tracing as `o` (a `path` integrator, or one rendered by Sahara's
/// path tracer) asks for it: Mitsuba's `max_depth` counts the emitter
/// seen, Sahara's bounces.
fn path<'a>(b: &mut Builder<'a>, o: &Object<'a>) -> Result<Integrator, FormatError> {
    let depth = o.int("max_depth", -1)?;
    let rr = o.int("rr_depth", 5)?;
    if o.bool("hide_emitters", false)? {
        b.w.add(
            format!(
                "{}: 'hide_emitters' is not supported; emitters are seen",
                o.what()
            ),
            &o.node.loc,
        );
    }
    let max_depth = match depth {
        d if d < 0 => MAX_DEPTH,
        0 | 1 => {
            b.w.add(
                format!(
                    "{}: max_depth {depth} ({}) is rendered with max_depth 2 (direct light)",
                    o.what(),
                    if depth == 0 {
                        "nothing"
                    } else {
                        "emitters only"
                    }
                ),
                &o.node.loc,
            );
            1
        }
        d => (d - 1).min(i64::from(MAX_DEPTH)) as u32,
    };
    if rr < 0 {
        return Err(o.error("rr_depth must be >= 0"));
    }
    Ok(Integrator::Path {
        max_depth,
        rr_depth: rr.min(i64::from(MAX_DEPTH)) as u32,
    })
}

/// Stochastic progressive photon mapping as `o` (an `sppm` or Mitsuba
/// 0.6's `photonmapper`) asks for it.
fn sppm<'a>(b: &mut Builder<'a>, o: &Object<'a>, node: &Node) -> Result<Integrator, FormatError> {
    let radius = o.float("initial_radius", 0.0)?;
    let photons = o.int("photon_count", 0)?;
    for k in ["alpha", "granularity", "max_passes"] {
        o.get(k);
    }
    if o.ty == "photonmapper" {
        b.w.add(
            "integrator 'photonmapper' is rendered by stochastic progressive photon mapping (sppm)",
            &node.loc,
        );
    }
    Ok(match path(b, o)? {
        Integrator::Path { max_depth, .. } => Integrator::Sppm {
            max_depth,
            radius: if radius.is_finite() && radius > 0.0 {
                radius as f32
            } else {
                0.0
            },
            photons: photons.clamp(0, i64::from(u32::MAX)) as u32,
        },
        other => other,
    })
}

/// The integrator `node` asks for (Mitsuba's default without one: path
/// tracing, unlimited depth, roulette from depth 5).
pub(crate) fn integrator<'a>(
    b: &mut Builder<'a>,
    node: Option<&'a Node>,
) -> Result<Integrator, FormatError> {
    let Some(node) = node else {
        return Ok(Integrator::Path {
            max_depth: MAX_DEPTH,
            rr_depth: 5,
        });
    };
    let o = b.object(node)?;
    let out = match o.ty {
        "path" => path(b, &o)?,
        // Mitsuba's particle tracer is light tracing.
        "ptracer" => {
            for k in ["samples_per_pass", "timeout", "hide_emitters"] {
                o.get(k);
            }
            match path(b, &o)? {
                Integrator::Path { max_depth, .. } => Integrator::LightPath { max_depth },
                other => other,
            }
        }
        // Mitsuba 0.6's bidirectional and photon-mapping plugins.
        "bdpt" => {
            for k in ["light_image", "sample_direct"] {
                o.get(k);
            }
            match path(b, &o)? {
                Integrator::Path { max_depth, .. } => Integrator::Bdpt { max_depth },
                other => other,
            }
        }
        "sppm" | "photonmapper" => sppm(b, &o, node)?,
        "volpath" | "volpathmis" => {
            o.get("samples_per_pass");
            o.get("timeout");
            path(b, &o)?
        }
        "prb" | "prb_basic" | "prbvolpath" => {
            b.w.add(
                format!("integrator '{}' is rendered by Sahara's path tracer", o.ty),
                &node.loc,
            );
            for k in ["samples_per_pass", "timeout"] {
                o.get(k);
            }
            path(b, &o)?
        }
        "direct" => {
            for k in ["emitter_samples", "bsdf_samples", "shading_samples"] {
                o.int(k, 1)?;
            }
            if o.bool("hide_emitters", false)? {
                b.w.add(
                    "integrator 'direct': 'hide_emitters' is not supported; emitters are seen",
                    &node.loc,
                );
            }
            Integrator::Path {
                max_depth: 1,
                rr_depth: MAX_DEPTH,
            }
        }
        "depth" => Integrator::Depth,
        "aov" => {
            o.get("aovs");
            b.w.add("integrator 'aov': only the image is rendered", &node.loc);
            let inner = o.nested("integrator");
            let out = integrator(b, inner.first().copied())?;
            o.warn_unused(&mut b.w);
            return Ok(out);
        }
        "mlt" | "pssmlt" => {
            b.w.add(
                format!(
                    "integrator '{}' is rendered by bidirectional path tracing (bdpt), which converges to the same image",
                    o.ty
                ),
                &node.loc,
            );
            o.mark_all_used();
            match path(b, &o)? {
                Integrator::Path { max_depth, .. } => Integrator::Bdpt { max_depth },
                other => other,
            }
        }
        "stokes" | "moment" => {
            b.w.add(
                format!("integrator '{}' is replaced by Sahara's path tracer", o.ty),
                &node.loc,
            );
            o.mark_all_used();
            path(b, &o)?
        }
        other => return Err(o.error(format!("unknown integrator type '{other}'"))),
    };
    o.warn_unused(&mut b.w);
    Ok(out)
}
