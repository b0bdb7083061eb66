//! Measured complex indices of refraction of common metals, at the three
//! wavelengths that stand for the red, green and blue channels.
//!
//! Sources (optical constants `n`, `k` tabulated against photon energy):
//! - gold, silver, copper: P. B. Johnson, R. W. Christy, "Optical
//!   constants of the noble metals", *Physical Review B* 6(12), 4370-4379,
//!   1972, table 1;
//! - aluminium: H.-J. Hagemann, W. Gudat, C. Kunz, "Optical constants from
//!   the far infrared to the x-ray region: Mg, Al, Cu, Ag, Au, Bi, C, and
//!   Al2O3", DESY report SR-74/7, 1974, table 3.
//!
//! Each preset is the table's values linearly interpolated in photon
//! energy at 650 nm (red), 550 nm (green) and 450 nm (blue), the
//! neighbouring rows being kept below.

use glam::Vec3;

/// `hc` in eV nm: a wavelength in nm is `HC / energy`.
const HC: f32 = 1239.842;

/// The wavelengths, nm, of the red, green and blue channels.
pub const RGB_WAVELENGTHS: [f32; 3] = [650.0, 550.0, 450.0];

/// Rows `(photon energy eV, n, k)` of a measured table around the three
/// wavelengths, in increasing energy.
type Rows = &'static [(f32, f32, f32)];

/// Gold, Johnson & Christy 1972.
const GOLD: Rows = &[
    (1.88, 0.14, 3.697),
    (2.01, 0.21, 3.272),
    (2.13, 0.29, 2.863),
    (2.26, 0.43, 2.455),
    (2.75, 1.38, 1.914),
    (2.88, 1.45, 1.948),
];

/// Silver, Johnson & Christy 1972.
const SILVER: Rows = &[
    (1.88, 0.05, 4.483),
    (2.01, 0.06, 4.152),
    (2.13, 0.05, 3.858),
    (2.26, 0.06, 3.586),
    (2.75, 0.04, 2.657),
    (2.88, 0.04, 2.462),
];

/// Copper, Johnson & Christy 1972.
const COPPER: Rows = &[
    (1.88, 0.22, 3.747),
    (2.01, 0.30, 3.205),
    (2.13, 0.70, 2.704),
    (2.26, 1.02, 2.577),
    (2.75, 1.24, 2.397),
    (2.88, 1.25, 2.305),
];

/// Aluminium, Hagemann, Gudat & Kunz 1974 (rows at 688.8, 619.9, 495.9
/// and 413.3 nm).
const ALUMINIUM: Rows = &[
    (HC / 688.8, 1.731, 7.96),
    (HC / 619.9, 1.292, 7.28),
    (HC / 495.9, 0.771, 5.91),
    (HC / 413.3, 0.548, 5.00),
];

/// `(n, k)` of `rows` at `wavelength` nm, linear in photon energy.
fn at(rows: Rows, wavelength: f32) -> (f32, f32) {
    let e = HC / wavelength;
    let i = rows
        .windows(2)
        .position(|w| e >= w[0].0 && e <= w[1].0)
        .expect("the tables bracket the channel wavelengths");
    let ((e0, n0, k0), (e1, n1, k1)) = (rows[i], rows[i + 1]);
    let t = (e - e0) / (e1 - e0);
    (n0 + (n1 - n0) * t, k0 + (k1 - k0) * t)
}

/// The names [`preset`] knows.
pub const PRESETS: [&str; 4] = ["gold", "silver", "copper", "aluminium"];

/// The complex index `(eta, k)` per RGB channel of a named metal (`gold`,
/// `silver`, `copper`, `aluminium`, also spelt `aluminum`).
pub fn preset(name: &str) -> Option<(Vec3, Vec3)> {
    let rows = match name {
        "gold" => GOLD,
        "silver" => SILVER,
        "copper" => COPPER,
        "aluminium" | "aluminum" => ALUMINIUM,
        _ => return None,
    };
    let [r, g, b] = RGB_WAVELENGTHS.map(|w| at(rows, w));
    Some((Vec3::new(r.0, g.0, b.0), Vec3::new(r.1, g.1, b.1)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::fresnel::conductor;

    #[test]
    fn presets_look_like_their_metals() {
        let f0 = |name| {
            let (eta, k) = preset(name).unwrap();
            conductor(1.0, eta, k)
        };
        // Gold and copper are warm (red > green > blue), silver and
        // aluminium nearly neutral and bright.
        let (gold, copper) = (f0("gold"), f0("copper"));
        assert!(gold.x > gold.y && gold.y > gold.z && gold.x > 0.9, "{gold}");
        assert!(copper.x > copper.y && copper.y > copper.z, "{copper}");
        for name in ["silver", "aluminium"] {
            let c = f0(name);
            assert!(c.min_element() > 0.85 && c.max_element() - c.min_element() < 0.1);
        }
        assert_eq!(preset("aluminum"), preset("aluminium"));
        assert!(preset("brass").is_none());
        // Gold at 550 nm lies between its table rows at 2.13 and 2.26 eV.
        let (eta, _) = preset("gold").unwrap();
        assert!(eta.y > 0.29 && eta.y < 0.43);
    }
}
