//! Spectral values as linear sRGB, converted once at load.
//!
//! pbrt-v4 renders spectrally; Sahara renders RGB. What this loses:
//! dispersion (an index of refraction is taken at one wavelength), the
//! exact product of spectra (a light's colour times a surface's is done in
//! RGB), and the shape of measured conductor spectra (eta and k are taken
//! at three wavelengths).
//!
//! - Colour matching: the CIE 1931 2° observer as the multi-lobe Gaussian
//!   fit of C. Wyman, P.-P. Sloan, P. Shirley, "Simple Analytic
//!   Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2),
//!   2013 (its equation 2), integrated from 360 to 830 nm in 1 nm steps.
//!   The fit is within a few per cent of the tabulated functions.
//! - XYZ to linear sRGB: the matrix of IEC 61966-2-1 (D65 white).
//! - Illuminants (`Illuminant` use) are normalised to luminance Y = 1, as
//!   pbrt-v4 normalises light spectra; an `rgb` light value is taken as
//!   is (pbrt-v4 scales it by its colour space's illuminant, D65, whose
//!   sRGB colour is white).
//! - Reflectances are integrated under an equal-energy illuminant and
//!   balanced so that a constant spectrum gives a grey of the same value.
//! - Unbounded values (eta, k) are sampled at 630, 532 and 465 nm for red,
//!   green and blue.

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

/// Wavelengths (nm) at which red, green and blue sample an unbounded spectrum.
pub(crate) const RGB_WAVELENGTHS: [f64; 3] = [630.0, 532.0, 465.0];

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
        Use::Reflectance => {
            let xyz = integrate_xyz(&s);
            let white = integrate_xyz(|_| 1.0);
            let rgb = xyz_to_srgb(xyz.map(|v| v / white[1]));
            let w = xyz_to_srgb(white.map(|v| v / white[1]));
            [rgb[0] / w[0], rgb[1] / w[1], rgb[2] / w[2]]
        }
    }
}

/// A black body's colour at `kelvin` as an illuminant (luminance 1).
pub(crate) fn blackbody_rgb(kelvin: f64) -> [f64; 3] {
    spectrum_to_rgb(|l| planck(l, kelvin), Use::Illuminant)
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

/// Optical constants of metals at 630, 532 and 465 nm, (eta, k), and
/// refractive indices of glasses at the d line (587.6 nm).
///
/// Metals: approximate values of the measured n, k data collected in E. D.
/// Palik (ed.), *Handbook of Optical Constants of Solids*, Academic Press,
/// 1985, near the three wavelengths (two or three digits; good to a few
/// per cent, which is what an RGB renderer can use). Glasses: the catalogue
/// value n_d of each (SCHOTT optical glass data sheets); a glass's index
/// is the same for all three channels (no dispersion).
const METALS: &[(&str, [f64; 3], [f64; 3])] = &[
    ("Ag", [0.155, 0.117, 0.138], [4.83, 3.12, 2.15]),
    ("Al", [1.66, 0.880, 0.521], [9.22, 6.27, 4.84]),
    ("Au", [0.143, 0.374, 1.44], [3.98, 2.39, 1.60]),
    ("Cu", [0.200, 0.924, 1.10], [3.91, 2.45, 2.14]),
    ("CuZn", [0.444, 0.527, 1.09], [3.70, 2.77, 1.83]),
    ("MgO", [1.73, 1.74, 1.75], [0.0, 0.0, 0.0]),
];

const GLASSES: &[(&str, f64)] = &[
    ("BK7", 1.5168),
    ("BAF10", 1.6700),
    ("FK51A", 1.4866),
    ("LASF9", 1.8503),
    ("F5", 1.6034),
    ("F10", 1.6200),
    ("F11", 1.6209),
    ("SF5", 1.6727),
    ("SF10", 1.7283),
    ("SF11", 1.7847),
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

/// Reflectance at normal incidence of a conductor with index `eta` and
/// extinction `k` (the exact Fresnel equations at zero angle).
pub(crate) fn conductor_f0(eta: f64, k: f64) -> f64 {
    let num = (eta - 1.0) * (eta - 1.0) + k * k;
    let den = (eta + 1.0) * (eta + 1.0) + k * k;
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn constant_reflectance_is_grey_and_named_metals_have_their_colour() {
        let g = spectrum_to_rgb(|_| 0.4, Use::Reflectance);
        assert!(g.iter().all(|c| (c - 0.4).abs() < 1e-9), "{g:?}");
        let Some(Named::Rgb(eta)) = named("metal-Au-eta") else {
            panic!()
        };
        let Some(Named::Rgb(k)) = named("metal-Au-k") else {
            panic!()
        };
        let f0: Vec<f64> = (0..3).map(|i| conductor_f0(eta[i], k[i])).collect();
        // Gold's normal reflectance in linear sRGB is about (1.0, 0.77, 0.33).
        assert!(
            f0[0] > 0.9 && (f0[1] - 0.8).abs() < 0.08 && (f0[2] - 0.33).abs() < 0.08,
            "{f0:?}"
        );
        let Some(Named::Rgb(ag)) = named("metal-Ag-eta") else {
            panic!()
        };
        let Some(Named::Rgb(agk)) = named("metal-Ag-k") else {
            panic!()
        };
        assert!((0..3).all(|i| conductor_f0(ag[i], agk[i]) > 0.9));
        assert_eq!(named("glass-BK7"), Some(Named::Rgb([1.5168; 3])));
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
