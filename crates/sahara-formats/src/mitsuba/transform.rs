//! `<transform>`: a sequence of `translate`, `rotate`, `scale`, `matrix`
//! and `lookat`, each applied after the ones before it (the result is
//! the last one times ... times the first), as Mitsuba composes them.
//!
//! - `translate`, `scale`: `x`, `y`, `z` attributes (missing ones 0 for a
//!   translation, 1 for a scale) or `value="x, y, z"`; a scale's single
//!   `value` is uniform.
//! - `rotate`: an axis (`x`, `y`, `z` or `value`) and an `angle` in
//!   degrees, right-handed.
//! - `matrix`: 16 values row by row (or 9 for the linear part).
//! - `lookat`: `origin`, `target`, `up` (optional); the frame's `+z`
//!   looks at the target, its `+x` is `up x z` and its `+y` the up
//!   direction made orthogonal.

use glam::{DMat3, DMat4, DVec3};
use sahara_readers::FormatError;

use super::spectra::numbers;
use super::xml::Node;

/// Three numbers from `x`, `y`, `z` attributes (`missing` for absent
/// ones) or from `value`.
fn triple(node: &Node, missing: f64) -> Result<DVec3, FormatError> {
    if let Some(v) = node.attr("value") {
        return match numbers(node, v)?[..] {
            [x, y, z] => Ok(DVec3::new(x, y, z)),
            [s] if node.tag == "scale" => Ok(DVec3::splat(s)),
            ref v => Err(node.error(format!(
                "<{}> value takes 3 numbers, found {}",
                node.tag,
                v.len()
            ))),
        };
    }
    let one = |k: &str| -> Result<f64, FormatError> {
        match node.attr(k) {
            None => Ok(missing),
            Some(t) => match numbers(node, t)?[..] {
                [v] => Ok(v),
                _ => Err(node.error(format!("<{}> {k}: expected one number", node.tag))),
            },
        }
    };
    Ok(DVec3::new(one("x")?, one("y")?, one("z")?))
}

/// A point given as `"x, y, z"` in attribute `name` of `node`.
fn point_attr(node: &Node, name: &str) -> Result<Option<DVec3>, FormatError> {
    let Some(t) = node.attr(name) else {
        return Ok(None);
    };
    match numbers(node, t)?[..] {
        [x, y, z] => Ok(Some(DVec3::new(x, y, z))),
        ref v => Err(node.error(format!(
            "<lookat> {name} takes 3 numbers, found {}",
            v.len()
        ))),
    }
}

/// Mitsuba's look-at frame: object to world for a frame at `origin`
/// whose `+z` looks at `target`.
pub(crate) fn look_at(origin: DVec3, target: DVec3, up: Option<DVec3>) -> Option<DMat4> {
    let dir = (target - origin).try_normalize()?;
    let up = match up {
        Some(u) => u,
        // Any direction not along the view.
        None if dir.x.abs() < 0.9 => DVec3::X,
        None => DVec3::Y,
    };
    let left = up.cross(dir).try_normalize()?;
    let new_up = dir.cross(left);
    Some(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}

/// The matrix of one operation.
fn operation(node: &Node) -> Result<DMat4, FormatError> {
    Ok(match node.tag.as_str() {
        "translate" => DMat4::from_translation(triple(node, 0.0)?),
        "scale" => {
            let s = triple(node, 1.0)?;
            DMat4::from_scale(s)
        }
        "rotate" => {
            let axis = triple(node, 0.0)?;
            let angle = match node.attr("angle") {
                Some(t) => match numbers(node, t)?[..] {
                    [a] => a,
                    _ => return Err(node.error("<rotate> angle: expected one number")),
                },
                None => return Err(node.error("<rotate> needs an 'angle' attribute (degrees)")),
            };
            let Some(axis) = axis.try_normalize() else {
                return Err(node.error("<rotate> needs a non-zero axis (x, y, z or value)"));
            };
            DMat4::from_axis_angle(axis, angle.to_radians())
        }
        "matrix" => {
            let v = numbers(node, node.need("value")?)?;
            match v.len() {
                16 => DMat4::from_cols_array(&[
                    v[0], v[4], v[8], v[12], v[1], v[5], v[9], v[13], v[2], v[6], v[10], v[14],
                    v[3], v[7], v[11], v[15],
                ]),
                9 => DMat4::from_mat3(DMat3::from_cols_array(&[
                    v[0], v[3], v[6], v[1], v[4], v[7], v[2], v[5], v[8],
                ])),
                n => {
                    return Err(node.error(format!(
                        "<matrix> takes 16 values (or 9), row by row; found {n}"
                    )))
                }
            }
        }
        "lookat" | "lookAt" => {
            let origin = point_attr(node, "origin")?
                .ok_or_else(|| node.error("<lookat> needs an 'origin' attribute"))?;
            let target = point_attr(node, "target")?
                .ok_or_else(|| node.error("<lookat> needs a 'target' attribute"))?;
            let up = point_attr(node, "up")?;
            look_at(origin, target, up).ok_or_else(|| {
                node.error("<lookat>: the origin is the target, or 'up' is along the view")
            })?
        }
        other => {
            return Err(node.error(format!(
                "unknown transform <{other}> (expected translate, rotate, scale, matrix or lookat)"
            )))
        }
    })
}

/// The matrix of a `<transform>` element.
pub(crate) fn parse_transform(node: &Node) -> Result<DMat4, FormatError> {
    let mut m = DMat4::IDENTITY;
    for op in &node.children {
        m = operation(op)? * m;
    }
    if !m.is_finite() {
        return Err(node.error("the transform is not finite"));
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(ops: &[(&str, &[(&str, &str)])]) -> Result<DMat4, FormatError> {
        let n = |tag: &str, attrs: &[(&str, &str)]| Node::at(tag, attrs, 2, 3);

        let mut root = n("transform", &[("name", "to_world")]);
        root.children = ops.iter().map(|(tag, a)| n(tag, a)).collect();
        parse_transform(&root)
    }

    fn close(a: DVec3, b: [f64; 3]) -> bool {
        (a - DVec3::from_array(b)).length() < 1e-12
    }

    #[test]
    fn operations_apply_in_order() {
        // Scale, then rotate 90 degrees about z, then translate.
        let m = t(&[
            ("scale", &[("value", "2")]),
            ("rotate", &[("z", "1"), ("angle", "90")]),
            ("translate", &[("x", "1"), ("y", "2"), ("z", "3")]),
        ])
        .unwrap();
        assert!(close(m.transform_point3(DVec3::X), [1.0, 4.0, 3.0]));
        let m = t(&[("rotate", &[("value", "0, 1, 0"), ("angle", "90")])]).unwrap();
        assert!(close(m.transform_point3(DVec3::Z), [1.0, 0.0, 0.0]));
        let m = t(&[("scale", &[("x", "2")])]).unwrap();
        assert!(close(m.transform_point3(DVec3::ONE), [2.0, 1.0, 1.0]));
    }

    #[test]
    fn matrices_are_row_major_and_lookat_is_mitsubas_frame() {
        let m = t(&[("matrix", &[("value", "1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1")])]).unwrap();
        assert!(close(m.transform_point3(DVec3::ZERO), [5.0, 6.0, 7.0]));
        let m = t(&[(
            "lookat",
            &[
                ("origin", "0, 0, 5"),
                ("target", "0 0 0"),
                ("up", "0, 1, 0"),
            ],
        )])
        .unwrap();
        assert!(close(m.transform_point3(DVec3::ZERO), [0.0, 0.0, 5.0]));
        assert!(close(m.transform_vector3(DVec3::Z), [0.0, 0.0, -1.0]));
        // +x is up x forward: looking down -z with y up, +x is world -x.
        assert!(close(m.transform_vector3(DVec3::X), [-1.0, 0.0, 0.0]));
        assert!(close(m.transform_vector3(DVec3::Y), [0.0, 1.0, 0.0]));
        let e = t(&[("matrix", &[("value", "1 2 3")])])
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "t.xml: line 2: column 3: <matrix> takes 16 values (or 9), row by row; found 3"
        );
        let e = t(&[("shear", &[])]).unwrap_err().to_string();
        assert!(e.contains("unknown transform <shear>"), "{e}");
    }
}
