//! Spectral values as linear sRGB, converted once at load.
//!
//! pbrt-v4 renders spectrally; Sahara renders RGB. What this loses:
//! dispersion (a glass has one index of refraction), the exact product of
//! spectra (a light's colour times a surface's is done in RGB), and the
//! shape of measured conductor spectra between the channels.
//!
//! - Colour matching: the CIE 1931 2° observer as the multi-lobe Gaussian
//!   fit of C. Wyman, P.-P. Sloan, P. Shirley, "Simple Analytic
//!   Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2),
//!   2013 (its equation 2), integrated from 360 to 830 nm in 1 nm steps.
//!   The fit is within a few per cent of the tabulated functions; the
//!   metal colours it gives are within 0.003 of those computed with the
//!   tables (see the tests).
//! - XYZ to linear sRGB: the matrix of IEC 61966-2-1 (D65 white).
//! - Illuminants (`Illuminant` use) are normalised to luminance Y = 1, as
//!   pbrt-v4 normalises light spectra; an `rgb` light value is taken as
//!   is (pbrt-v4 scales it by its colour space's illuminant, D65, whose
//!   sRGB colour is white).
//! - Reflectances are the colour of the light they reflect under CIE
//!   standard illuminant D65 (sRGB's white, and what an `rgb` light is in
//!   pbrt-v4), balanced so that a constant spectrum is the same grey.
//! - Conductors: the exact Fresnel reflectance of the spectra `eta(λ)`,
//!   `k(λ)` is turned into an RGB reflectance at each angle as above, and
//!   each channel gets the `eta`, `k` whose Fresnel curve has that normal
//!   reflectance exactly and follows the curve best over all angles
//!   ([`fit_conductor`]).
//! - Other unbounded values (a dielectric's index given as a spectrum) are
//!   taken at the d line, 587.56 nm, where glass catalogues give `n_d`.

use glam::Vec3;
use sahara_render::fresnel;

/// How a spectrum is used, which decides how it becomes RGB.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Use {
    /// Emitted light: normalised to luminance 1.
    Illuminant,
    /// A reflectance in [0, 1].
    Reflectance,
    /// An index of refraction or extinction coefficient.
    Unbounded,
}

/// Wavelengths (nm) at which red, green and blue sample an unbounded
/// spectrum: those of the renderer's metal presets.
pub(crate) const RGB_WAVELENGTHS: [f64; 3] = [
    sahara_render::metals::RGB_WAVELENGTHS[0] as f64,
    sahara_render::metals::RGB_WAVELENGTHS[1] as f64,
    sahara_render::metals::RGB_WAVELENGTHS[2] as f64,
];

/// The d line of helium (nm): glass catalogues give the index `n_d` there.
pub(crate) const D_LINE: f64 = 587.56;

/// CIE standard illuminant D65, relative spectral power at 360, 365, ...,
/// 830 nm (CIE 15:2004, table T.1; ISO 11664-2).
const D65: [f64; 95] = [
    46.6383, 49.3637, 52.0891, 51.0323, 49.9755, 52.3118, 54.6482, 68.7015, 82.7549, 87.1204,
    91.486, 92.4589, 93.4318, 90.057, 86.6823, 95.7736, 104.865, 110.936, 117.008, 117.41, 117.812,
    116.336, 114.861, 115.392, 115.923, 112.367, 108.811, 109.082, 109.354, 108.578, 107.802,
    106.296, 104.79, 106.239, 107.689, 106.047, 104.405, 104.225, 104.046, 102.023, 100.0, 98.1671,
    96.3342, 96.0611, 95.788, 92.2368, 88.6856, 89.3459, 90.0062, 89.8026, 89.5991, 88.6489,
    87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.863, 80.0268, 80.1207, 80.2146, 81.2462,
    82.2778, 80.281, 78.2842, 74.0027, 69.7213, 70.6652, 71.6091, 72.979, 74.349, 67.9765, 61.604,
    65.7448, 69.8856, 72.4863, 75.087, 69.3398, 63.5927, 55.0054, 46.4182, 56.6118, 66.8054,
    65.0941, 63.3828, 63.8434, 64.304, 61.8779, 59.4519, 55.7054, 51.959, 54.6998, 57.4406,
    58.8765, 60.3125,
];

/// D65 at `lambda` nm (linear between the table's rows, 0 outside it).
pub(crate) fn d65(lambda: f64) -> f64 {
    let x = (lambda - 360.0) / 5.0;
    if !(0.0..=94.0).contains(&x) {
        return 0.0;
    }
    let i = (x.floor() as usize).min(93);
    let t = x - i as f64;
    D65[i] + (D65[i + 1] - D65[i]) * t
}

/// The piecewise Gaussian of the fit: `sigma1` left of `mu`, `sigma2` right.
fn lobe(lambda: f64, mu: f64, sigma1: f64, sigma2: f64) -> f64 {
    let s = if lambda < mu { sigma1 } else { sigma2 };
    let t = (lambda - mu) / s;
    (-0.5 * t * t).exp()
}

/// The CIE 1931 2° colour matching functions at `lambda` nm (Wyman et al. 2013).
pub(crate) fn cie_xyz(lambda: f64) -> [f64; 3] {
    let x = 1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7)
        - 0.065 * lobe(lambda, 501.1, 20.4, 26.2);
    let y = 0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1);
    let z = 1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8);
    [x, y, z]
}

/// Linear sRGB of CIE XYZ (IEC 61966-2-1).
pub(crate) fn xyz_to_srgb([x, y, z]: [f64; 3]) -> [f64; 3] {
    [
        3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
        -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
        0.0556434 * x - 0.2040259 * y + 1.0572252 * z,
    ]
}

/// XYZ of `s` integrated against the matching functions, 360..=830 nm.
pub(crate) fn integrate_xyz(s: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut out = [0.0; 3];
    for l in 360..=830 {
        let lambda = f64::from(l);
        let v = s(lambda);
        let c = cie_xyz(lambda);
        for i in 0..3 {
            out[i] += v * c[i];
        }
    }
    out
}

/// Planck's law: spectral radiance of a black body at `kelvin`, `lambda` in nm (unnormalised).
pub(crate) fn planck(lambda: f64, kelvin: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l = lambda * 1e-9;
    2.0 * H * C * C / (l.powi(5) * ((H * C / (l * KB * kelvin)).exp() - 1.0))
}

/// The linear sRGB of spectrum `s` used as `usage`.
pub(crate) fn spectrum_to_rgb(s: impl Fn(f64) -> f64, usage: Use) -> [f64; 3] {
    match usage {
        Use::Unbounded => RGB_WAVELENGTHS.map(&s),
        Use::Illuminant => {
            let xyz = integrate_xyz(&s);
            if xyz[1] <= 0.0 {
                return [0.0; 3];
            }
            xyz_to_srgb(xyz.map(|v| v / xyz[1]))
        }
        Use::Reflectance => reflectance_rgb(s),
    }
}

/// The linear sRGB of a reflectance spectrum: the colour of the light it
/// reflects under D65, divided by that of a perfect white.
pub(crate) fn reflectance_rgb(s: impl Fn(f64) -> f64) -> [f64; 3] {
    let white = integrate_xyz(d65);
    let rgb = xyz_to_srgb(integrate_xyz(|l| s(l) * d65(l)).map(|v| v / white[1]));
    let w = xyz_to_srgb(white.map(|v| v / white[1]));
    [rgb[0] / w[0], rgb[1] / w[1], rgb[2] / w[2]]
}

/// Cosines of the angles over which [`fit_conductor`] matches Fresnel
/// curves: the midpoints of 16 equal steps in `cos`.
const FIT_COSINES: usize = 16;

/// Per-channel `(eta, k)` of a conductor whose spectral indices are
/// `eta(λ)` and `k(λ)` (λ in nm).
///
/// For each channel, the target is the RGB reflectance
/// ([`reflectance_rgb`]) of the spectral Fresnel reflectance at each angle.
/// The normal reflectance `r` is matched exactly (at most 0.999: a colour
/// out of the sRGB gamut, like gold's red, is clipped), and the curve
/// over angles in the least-squares sense, weighted by the cosine, by a
/// search over the one-parameter family of `(eta, k)` with that `r`:
/// O. Gulbrandsen, "Artist Friendly Metallic Fresnel", JCGT 3(4), 2014,
/// `eta = g n_min + (1 - g) n_max` with `n_min = (1 - r) / (1 + r)`,
/// `n_max = (1 + sqrt r) / (1 - sqrt r)`, `k^2 = ((eta + 1)^2 r - (eta -
/// 1)^2) / (1 - r)`, `g` in `[0, 1]`.
pub(crate) fn fit_conductor(
    eta: impl Fn(f64) -> f64,
    k: impl Fn(f64) -> f64,
) -> ([f64; 3], [f64; 3]) {
    let spectral = |c: f64, l: f64| {
        let e = Vec3::splat(eta(l) as f32);
        let kk = Vec3::splat(k(l) as f32);
        f64::from(fresnel::conductor(c as f32, e, kk).x)
    };
    let cosines: Vec<f64> = (0..FIT_COSINES)
        .map(|j| (j as f64 + 0.5) / FIT_COSINES as f64)
        .collect();
    let targets: Vec<[f64; 3]> = cosines
        .iter()
        .map(|&c| reflectance_rgb(|l| spectral(c, l)))
        .collect();
    let normal = reflectance_rgb(|l| spectral(1.0, l));
    let mut out_eta = [1.0; 3];
    let mut out_k = [0.0; 3];
    for ch in 0..3 {
        let r = normal[ch].clamp(0.0, 0.999);
        if r <= 0.0 {
            continue;
        }
        let family = |g: f64| {
            let n_min = (1.0 - r) / (1.0 + r);
            let n_max = (1.0 + r.sqrt()) / (1.0 - r.sqrt());
            let n = g * n_min + (1.0 - g) * n_max;
            let k2 = ((n + 1.0) * (n + 1.0) * r - (n - 1.0) * (n - 1.0)) / (1.0 - r);
            (n, k2.max(0.0).sqrt())
        };
        let error = |g: f64| {
            let (n, kk) = family(g);
            let (e, kv) = (Vec3::splat(n as f32), Vec3::splat(kk as f32));
            cosines
                .iter()
                .zip(&targets)
                .map(|(&c, t)| {
                    let d = f64::from(fresnel::conductor(c as f32, e, kv).x) - t[ch];
                    c * d * d
                })
                .sum::<f64>()
        };
        // A coarse scan, then golden-section search around its best point.
        let steps = 64;
        let best = (0..=steps)
            .map(|i| i as f64 / steps as f64)
            .min_by(|a, b| error(*a).total_cmp(&error(*b)))
            .unwrap_or(0.0);
        let (mut lo, mut hi) = (
            (best - 1.0 / steps as f64).max(0.0),
            (best + 1.0 / steps as f64).min(1.0),
        );
        let phi = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..40 {
            let (a, b) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
            if error(a) < error(b) {
                hi = b;
            } else {
                lo = a;
            }
        }
        let (n, kk) = family(0.5 * (lo + hi));
        out_eta[ch] = n;
        out_k[ch] = kk;
    }
    (out_eta, out_k)
}

/// A black body's colour at `kelvin` as an illuminant (luminance 1).
pub(crate) fn blackbody_rgb(kelvin: f64) -> [f64; 3] {
    spectrum_to_rgb(|l| planck(l, kelvin), Use::Illuminant)
}

/// The linear sRGB of pbrt-v4's normalised black body at `kelvin` (its
/// spectral radiance over that at its peak, so 1 at the peak) taken as
/// radiance (a spectrum of 1 everywhere has luminance 1), negative
/// components clipped: what a medium's temperature grid emits per unit of
/// absorption. Unlike [`blackbody_rgb`] it keeps the brightness: a
/// 1500 K body glows a dim red, a 6500 K one near white at 1.
pub(crate) fn blackbody_radiance_rgb(kelvin: f64) -> [f64; 3] {
    // Wien's displacement law: the peak's wavelength in nm.
    let peak = planck(2.897_771_955e6 / kelvin, kelvin);
    let y = integrate_xyz(|_| 1.0)[1];
    xyz_to_srgb(integrate_xyz(|l| planck(l, kelvin) / peak).map(|v| v / y)).map(|c| c.max(0.0))
}

/// A sampled spectrum, linear between its samples and constant beyond them.
pub(crate) fn piecewise_linear(pairs: &[(f64, f64)], lambda: f64) -> f64 {
    let Some(first) = pairs.first() else {
        return 0.0;
    };
    if lambda <= first.0 {
        return first.1;
    }
    for w in pairs.windows(2) {
        let ((l0, v0), (l1, v1)) = (w[0], w[1]);
        if lambda <= l1 {
            return v0 + (v1 - v0) * (lambda - l0) / (l1 - l0);
        }
    }
    pairs.last().expect("not empty").1
}

/// What a named spectrum of pbrt-v4 is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Named {
    /// A value per RGB wavelength (conductor eta or k, a glass's index).
    Rgb([f64; 3]),
    /// A black body at this temperature (standard illuminant A).
    Blackbody(f64),
    /// Standard illuminant D65: white in sRGB.
    White,
}

/// pbrt-v4's named conductors as the per-channel `(eta, k)` of
/// [`fit_conductor`], and its named glasses by their index `n_d`.
///
/// Metals (`metal-X-eta`, `metal-X-k`): fitted to the measured spectra
/// pbrt-v4 tabulates under these names (its `src/pbrt/util/spectrum.cpp`,
/// arrays `X_eta` and `X_k`), to 4 digits. The test
/// `named_metals_are_the_fits_of_pbrt_v4s_spectra` recomputes them from
/// that file when `PBRT_V4_SPECTRUM_CPP` names it; their normal
/// reflectances agree with the published linear sRGB values of Akenine-Möller
/// et al., *Real-Time Rendering*, 4th ed., 2018, table 9.2 (see the tests).
/// The tabulated spectra of MgO and TiO2 have `k = 0` (dielectrics).
const METALS: &[(&str, [f64; 3], [f64; 3])] = &[
    ("Ag", [0.1288, 0.1257, 0.1513], [4.0835, 3.3644, 2.4128]),
    ("Al", [1.4205, 0.9325, 0.5917], [7.7250, 6.6145, 5.3661]),
    ("Au", [0.3267, 0.4015, 1.5758], [36.1267, 2.3372, 1.7213]),
    ("Cu", [0.1812, 0.9732, 1.2127], [3.7469, 2.6234, 2.3673]),
    ("CuZn", [0.4797, 0.5226, 1.1281], [4.3158, 2.6754, 1.8135]),
    ("MgO", [1.7338, 1.7409, 1.7535], [0.0036, 0.0034, 0.0036]),
    ("TiO2", [2.8616, 2.9562, 3.1856], [0.0165, 0.0024, 0.0129]),
];

/// Glasses by their index at the d line, `n_d` (SCHOTT optical glass
/// catalogue: N-BK7, N-BAF10, N-FK51A, N-LASF9, SF5, SF10, SF11). pbrt-v4's
/// `glass-F5`, `-F10` and `-F11` hold the dispersion curves of SF5, SF10
/// and SF11 (its tables `GlassSF5_eta` ...), so they are those glasses.
/// Each agrees within 3e-5 with pbrt-v4's tabulated curve (from
/// refractiveindex.info) at 587.56 nm.
const GLASSES: &[(&str, f64)] = &[
    ("BK7", 1.5168),
    ("BAF10", 1.67003),
    ("FK51A", 1.48656),
    ("LASF9", 1.85025),
    ("F5", 1.6727),
    ("F10", 1.72825),
    ("F11", 1.78472),
];

/// pbrt-v4's named spectrum `name`, if Sahara knows it.
pub(crate) fn named(name: &str) -> Option<Named> {
    if let Some(metal) = name.strip_prefix("metal-") {
        let (m, part) = metal.rsplit_once('-')?;
        let &(_, eta, k) = METALS.iter().find(|(n, _, _)| *n == m)?;
        return match part {
            "eta" => Some(Named::Rgb(eta)),
            "k" => Some(Named::Rgb(k)),
            _ => None,
        };
    }
    if let Some(glass) = name.strip_prefix("glass-") {
        let &(_, n) = GLASSES.iter().find(|(g, _)| *g == glass)?;
        return Some(Named::Rgb([n; 3]));
    }
    match name {
        "stdillum-D65" => Some(Named::White),
        // CIE standard illuminant A: a black body at 2856 K.
        "stdillum-A" => Some(Named::Blackbody(2856.0)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reflectance at normal incidence of a conductor with index `eta` and
    /// extinction `k` (the exact Fresnel equations at zero angle).
    fn conductor_f0(eta: f64, k: f64) -> f64 {
        let num = (eta - 1.0) * (eta - 1.0) + k * k;
        let den = (eta + 1.0) * (eta + 1.0) + k * k;
        if den > 0.0 {
            num / den
        } else {
            0.0
        }
    }

    fn xy(xyz: [f64; 3]) -> (f64, f64) {
        let s = xyz[0] + xyz[1] + xyz[2];
        (xyz[0] / s, xyz[1] / s)
    }

    #[test]
    fn blackbody_chromaticities_match_the_cie_illuminants() {
        // Illuminant A is a black body at 2856 K: x = 0.44757, y = 0.40745
        // (CIE 15:2004, table T.3).
        let (x, y) = xy(integrate_xyz(|l| planck(l, 2856.0)));
        assert!(
            (x - 0.44757).abs() < 0.003 && (y - 0.40745).abs() < 0.003,
            "{x} {y}"
        );
        // The Planckian locus at 6500 K: x = 0.3135, y = 0.3237.
        let (x, y) = xy(integrate_xyz(|l| planck(l, 6500.0)));
        assert!(
            (x - 0.3135).abs() < 0.003 && (y - 0.3237).abs() < 0.003,
            "{x} {y}"
        );
    }

    #[test]
    fn illuminants_have_unit_luminance_and_warm_ones_are_red() {
        let rgb = blackbody_rgb(2700.0);
        let y = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
        assert!((y - 1.0).abs() < 0.02, "luminance {y}");
        assert!(rgb[0] > rgb[1] && rgb[1] > rgb[2], "{rgb:?}");
        let blue = blackbody_rgb(12000.0);
        assert!(blue[2] > blue[0], "{blue:?}");
    }

    fn metal(name: &str) -> ([f64; 3], [f64; 3]) {
        let part = |p: &str| match named(&format!("metal-{name}-{p}")) {
            Some(Named::Rgb(c)) => c,
            other => panic!("metal-{name}-{p}: {other:?}"),
        };
        (part("eta"), part("k"))
    }

    #[test]
    fn constant_reflectance_is_grey() {
        let g = spectrum_to_rgb(|_| 0.4, Use::Reflectance);
        assert!(g.iter().all(|c| (c - 0.4).abs() < 1e-9), "{g:?}");
    }

    /// The normal reflectance of each named metal in linear sRGB, as
    /// published by Akenine-Möller et al., Real-Time Rendering, 4th ed.,
    /// 2018, table 9.2 (brass is CuZn; gold's red, out of gamut, is 1 there).
    #[test]
    fn named_metals_reflect_their_published_colours() {
        for (name, f0) in [
            ("Ag", [0.972, 0.960, 0.915]),
            ("Al", [0.913, 0.922, 0.924]),
            ("Au", [1.000, 0.782, 0.344]),
            ("Cu", [0.955, 0.638, 0.538]),
            ("CuZn", [0.910, 0.778, 0.423]),
        ] {
            let (eta, k) = metal(name);
            for c in 0..3 {
                let r = conductor_f0(eta[c], k[c]);
                assert!(
                    (r - f0[c]).abs() < 0.004,
                    "{name} channel {c}: {r} against {}",
                    f0[c]
                );
            }
        }
    }

    /// A spectrally flat conductor is its own best fit: every channel
    /// recovers its eta and k.
    #[test]
    fn fitting_a_flat_conductor_recovers_it() {
        for (eta, k) in [(0.2, 3.0), (1.5, 7.0), (1.2, 0.5)] {
            let (fe, fk) = fit_conductor(|_| eta, |_| k);
            for c in 0..3 {
                assert!(
                    (fe[c] - eta).abs() < 2e-3 * eta.max(1.0)
                        && (fk[c] - k).abs() < 2e-3 * k.max(1.0),
                    "({eta}, {k}) fitted as ({}, {})",
                    fe[c],
                    fk[c]
                );
            }
        }
    }

    /// The named metals are the fits of pbrt-v4's tabulated spectra: with
    /// `PBRT_V4_SPECTRUM_CPP` naming pbrt-v4's `src/pbrt/util/spectrum.cpp`,
    /// each is recomputed from its arrays (and printed); without it the
    /// test checks nothing.
    #[test]
    fn named_metals_are_the_fits_of_pbrt_v4s_spectra() {
        let Ok(path) = std::env::var("PBRT_V4_SPECTRUM_CPP") else {
            return;
        };
        let src = std::fs::read_to_string(&path).expect("PBRT_V4_SPECTRUM_CPP is readable");
        let table = |array: &str| -> Vec<(f64, f64)> {
            let start = src
                .find(&format!("const Float {array}[] = {{"))
                .unwrap_or_else(|| panic!("{array} not in {path}"));
            let body = &src[start..];
            let body = &body[body.find('{').unwrap() + 1..body.find("};").unwrap()];
            let v: Vec<f64> = body
                .split(',')
                .filter_map(|t| t.trim().parse().ok())
                .collect();
            v.chunks_exact(2).map(|p| (p[0], p[1])).collect()
        };
        let mut wrong = Vec::new();
        for &(name, eta, k) in METALS {
            let (e, kk) = (table(&format!("{name}_eta")), table(&format!("{name}_k")));
            let (fe, fk) = fit_conductor(|l| piecewise_linear(&e, l), |l| piecewise_linear(&kk, l));
            println!("(\"{name}\", {fe:.4?}, {fk:.4?}),");
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-4 * b.abs().max(1.0);
            if !(0..3).all(|c| close(fe[c], eta[c]) && close(fk[c], k[c])) {
                wrong.push(name);
            }
        }
        assert!(wrong.is_empty(), "not the fits: {wrong:?}");
    }

    #[test]
    fn named_glasses_are_pbrt_v4s() {
        assert_eq!(named("glass-BK7"), Some(Named::Rgb([1.5168; 3])));
        // pbrt-v4's "glass-F5" is SF5.
        assert_eq!(named("glass-F5"), Some(Named::Rgb([1.6727; 3])));
        assert_eq!(named("glass-SF5"), None);
        assert_eq!(named("metal-Xx-eta"), None);
        assert!((conductor_f0(1.5, 0.0) - 0.04).abs() < 1e-12);
    }

    #[test]
    fn sampled_spectra_interpolate_and_clamp() {
        let s = [(400.0, 0.0), (500.0, 1.0)];
        assert_eq!(piecewise_linear(&s, 300.0), 0.0);
        assert_eq!(piecewise_linear(&s, 450.0), 0.5);
        assert_eq!(piecewise_linear(&s, 900.0), 1.0);
    }
}
