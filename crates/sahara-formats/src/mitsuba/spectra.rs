//! Mitsuba's colour values (`rgb`, `srgb`, `spectrum`, `blackbody`) and
//! their linear sRGB, computed as Mitsuba's RGB variants compute them,
//! with the spectral code shared with the pbrt reader ([`crate::common::spectrum`]).
//!
//! - `rgb` is linear sRGB as written; `srgb` (Mitsuba 0.x, also
//!   `#rrggbb`) is decoded from sRGB.
//! - A `spectrum` of one value is that grey.
//! - A sampled spectrum (`value="400:0.1, 500:0.5"`, or `filename` of an
//!   `.spd` file of such pairs) is piecewise linear between its samples:
//!   as a reflectance, the colour it reflects under D65 (sRGB's white)
//!   relative to a perfect white's; as an emitter's radiance, its CIE XYZ
//!   over the integral of `y` (Mitsuba's normalisation: a constant
//!   spectrum of 1 is white 1); as a conductor's `eta` or `k`, the two
//!   spectra fitted together ([`crate::common::spectrum::fit_conductor`]).
//! - A black body is normalised to luminance 1, as pbrt-v4 does (Mitsuba
//!   gives it in absolute units): a warning.

use std::path::Path;

use glam::{DVec3, Vec3};
use sahara_readers::FormatError;

use super::xml::Node;
use crate::common::spectrum;

/// A colour as the file gives it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Color {
    /// Linear sRGB.
    Rgb(DVec3),
    /// A constant spectrum.
    Uniform(f64),
    /// `(wavelength nm, value)` pairs, by increasing wavelength.
    Sampled(Vec<(f64, f64)>),
    /// A black body of this temperature (kelvin).
    Blackbody(f64),
}

/// How a colour is used, which decides how a spectrum becomes RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Usage {
    /// A reflectance or transmittance.
    Reflectance,
    /// Emitted radiance, intensity or irradiance.
    Emission,
    /// A conductor's `eta` or `k`, a dielectric's index.
    Index,
}

impl Color {
    /// The linear sRGB of this colour used as `usage`.
    pub(crate) fn rgb(&self, usage: Usage) -> Vec3 {
        let v = |c: [f64; 3]| DVec3::from_array(c).as_vec3();
        match self {
            Color::Rgb(c) => c.as_vec3(),
            Color::Uniform(g) => Vec3::splat(*g as f32),
            Color::Sampled(s) => {
                let f = |l: f64| spectrum::piecewise_linear(s, l);
                match usage {
                    Usage::Reflectance => v(spectrum::reflectance_rgb(f)),
                    Usage::Emission => {
                        let y = spectrum::integrate_xyz(|_| 1.0)[1];
                        v(spectrum::xyz_to_srgb(
                            spectrum::integrate_xyz(f).map(|c| c / y),
                        ))
                    }
                    Usage::Index => v(spectrum::RGB_WAVELENGTHS.map(f)),
                }
            }
            Color::Blackbody(t) => v(spectrum::blackbody_rgb(*t)),
        }
    }
}

/// The numbers of `text`, separated by commas and/or white space.
pub(crate) fn numbers(node: &Node, text: &str) -> Result<Vec<f64>, FormatError> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| node.error(format!("expected a number, found '{s}'")))
        })
        .collect()
}

/// An `<rgb>` (or, with `srgb`, an `<srgb>`) value: three numbers, one
/// for a grey, or (`srgb`) `#rrggbb`.
pub(crate) fn parse_rgb(node: &Node, srgb: bool) -> Result<Color, FormatError> {
    let text = node.need("value")?.trim();
    let decode = |v: f64| {
        if srgb {
            f64::from(sahara_render::srgb_to_linear(v as f32))
        } else {
            v
        }
    };
    if let Some(hex) = text.strip_prefix('#') {
        let bad = || node.error(format!("expected '#rrggbb', found '{text}'"));
        if !srgb || hex.len() != 6 {
            return Err(bad());
        }
        let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).map_err(|_| bad());
        let c = [byte(0)?, byte(2)?, byte(4)?].map(|b| decode(f64::from(b) / 255.0));
        return Ok(Color::Rgb(DVec3::from_array(c)));
    }
    match numbers(node, text)?[..] {
        [g] => Ok(Color::Rgb(DVec3::splat(decode(g)))),
        [r, g, b] => Ok(Color::Rgb(DVec3::new(decode(r), decode(g), decode(b)))),
        ref v => Err(node.error(format!(
            "<{}> takes 3 values (or 1 for a grey), found {}",
            node.tag,
            v.len()
        ))),
    }
}

/// A `<spectrum>` value: one number, `wavelength:value` pairs, or a file
/// of pairs (`filename`, one pair per line, `#` comments).
pub(crate) fn parse_spectrum(node: &Node, path: Option<&Path>) -> Result<Color, FormatError> {
    let (text, from) = match path {
        Some(p) => (
            std::fs::read_to_string(p).map_err(|e| {
                node.error(format!("{}: cannot read the spectrum: {e}", p.display()))
            })?,
            Some(p),
        ),
        None => (node.need("value")?.to_owned(), None),
    };
    let text: String = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    if from.is_none() && !text.contains(':') {
        return match numbers(node, &text)?[..] {
            [v] => Ok(Color::Uniform(v)),
            ref v => Err(node.error(format!(
                "<spectrum> takes one value or wavelength:value pairs, found {} values",
                v.len()
            ))),
        };
    }
    let mut pairs = Vec::new();
    if from.is_some() {
        let v = numbers(node, &text)?;
        if v.len() % 2 != 0 || v.is_empty() {
            return Err(node.error("the spectrum file holds no whole wavelength value pairs"));
        }
        pairs.extend(v.chunks_exact(2).map(|c| (c[0], c[1])));
    } else {
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let Some((l, v)) = item.split_once(':') else {
                return Err(node.error(format!("expected wavelength:value, found '{item}'")));
            };
            let [l, v] = [l, v].map(|s| numbers(node, s));
            match (&l?[..], &v?[..]) {
                ([l], [v]) => pairs.push((*l, *v)),
                _ => return Err(node.error(format!("expected wavelength:value, found '{item}'"))),
            }
        }
    }
    if pairs.windows(2).any(|p| p[1].0 <= p[0].0) {
        return Err(node.error("the wavelengths of a spectrum must increase"));
    }
    Ok(Color::Sampled(pairs))
}

/// A `<blackbody temperature="5000K"/>` (or `<spectrum
/// type="blackbody">` with a `temperature` float) value.
pub(crate) fn parse_temperature(node: &Node, text: &str) -> Result<Color, FormatError> {
    let t = text.trim().trim_end_matches(['K', 'k']);
    match numbers(node, t)?[..] {
        [k] if k > 0.0 => Ok(Color::Blackbody(k)),
        _ => Err(node.error(format!(
            "a black body's temperature must be one number of kelvin > 0, found '{text}'"
        ))),
    }
}

/// Converts the `(eta, k)` of a conductor given as two colours: two
/// sampled spectra are fitted together, anything else is taken channel
/// by channel.
pub(crate) fn conductor_rgb(eta: &Color, k: &Color) -> (Vec3, Vec3) {
    if let (Color::Sampled(a), Color::Sampled(b)) = (eta, k) {
        let (fe, fk) = spectrum::fit_conductor(
            |l| spectrum::piecewise_linear(a, l),
            |l| spectrum::piecewise_linear(b, l),
        );
        let v = |c: [f64; 3]| DVec3::from_array(c).as_vec3();
        return (v(fe), v(fk));
    }
    (eta.rgb(Usage::Index), k.rgb(Usage::Index))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(tag: &str, attrs: &[(&str, &str)]) -> Node {
        Node::at(tag, attrs, 1, 1)
    }

    #[test]
    fn rgb_takes_commas_or_spaces_and_srgb_is_decoded() {
        let c = parse_rgb(&node("rgb", &[("value", "0.1, 0.2 0.3")]), false).unwrap();
        assert_eq!(c, Color::Rgb(DVec3::new(0.1, 0.2, 0.3)));
        let c = parse_rgb(&node("rgb", &[("value", "0.5")]), false).unwrap();
        assert_eq!(c, Color::Rgb(DVec3::splat(0.5)));
        let c = parse_rgb(&node("srgb", &[("value", "#ff0000")]), true).unwrap();
        assert_eq!(c, Color::Rgb(DVec3::new(1.0, 0.0, 0.0)));
        let e = parse_rgb(&node("rgb", &[("value", "1 2")]), false).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.xml: line 1: column 1: <rgb> takes 3 values (or 1 for a grey), found 2"
        );
    }

    #[test]
    fn spectra_are_greys_or_sampled_and_convert_by_use() {
        let n = node("spectrum", &[("value", "0.25")]);
        assert_eq!(parse_spectrum(&n, None).unwrap(), Color::Uniform(0.25));
        let n = node(
            "spectrum",
            &[("value", "400:0.5, 500:0.5,600:0.5, 700:0.5")],
        );
        let c = parse_spectrum(&n, None).unwrap();
        // A constant reflectance is that grey.
        let r = c.rgb(Usage::Reflectance);
        assert!((r - Vec3::splat(0.5)).abs().max_element() < 1e-4, "{r}");
        // A constant emission of 1 has luminance 1 (equal energy is
        // slightly pink in sRGB).
        let one = Color::Sampled(vec![(360.0, 1.0), (830.0, 1.0)]).rgb(Usage::Emission);
        let y = one.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        assert!((y - 1.0).abs() < 1e-3, "{one}");
        let e = parse_spectrum(&node("spectrum", &[("value", "500:1, 400:2")]), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.ends_with("the wavelengths of a spectrum must increase"),
            "{e}"
        );
    }
}
