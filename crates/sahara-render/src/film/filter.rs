//! Pixel reconstruction filters (separable, evaluated in pixel units).

use crate::names::{name_table, Accepts, Named, Parameter};

/// A reconstruction filter; pixel estimates are `sum w L / sum w` over the
/// samples within its radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// 1 inside `|x|, |y| < radius`.
    Box {
        /// Half width in pixels (0.5: each sample counts for its own pixel).
        radius: f32,
    },
    /// `(1 - |x| / r)(1 - |y| / r)`.
    Tent {
        /// Half width in pixels.
        radius: f32,
    },
    /// A Gaussian minus its value at the radius, so it reaches zero there.
    Gaussian {
        /// Half width in pixels.
        radius: f32,
        /// Standard deviation in pixels.
        sigma: f32,
    },
    /// Mitchell and Netravali's cubic (1988), scaled to `radius`; its
    /// negative lobes can make pixel estimates negative, which the film
    /// clamps to zero.
    Mitchell {
        /// Half width in pixels (2 is the classic support).
        radius: f32,
        /// The B parameter.
        b: f32,
        /// The C parameter.
        c: f32,
    },
}

/// The filters by name, without their parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FilterKind {
    /// [`Filter::Box`].
    Box,
    /// [`Filter::Tent`].
    Tent,
    /// [`Filter::Gaussian`].
    Gaussian,
    /// [`Filter::Mitchell`].
    Mitchell,
}

name_table!(FilterKind, "filter", {
    FilterKind::Box => "box",
    FilterKind::Tent => "tent",
    FilterKind::Gaussian => "gaussian",
    FilterKind::Mitchell => "mitchell",
});

/// A filter's half width in pixels.
const fn radius(default: f32) -> Parameter {
    Parameter {
        name: "radius",
        default,
        accepts: Accepts::Positive,
    }
}

impl FilterKind {
    /// The parameters of this kind, in the order [`Filter::with_parameters`]
    /// takes them, with their defaults: a one-pixel box (radius 0.5), a
    /// tent of radius 1, a Gaussian of radius 1.5 and sigma 0.5,
    /// Mitchell-Netravali with B = C = 1/3 and radius 2.
    pub fn parameters(self) -> &'static [Parameter] {
        const THIRD: Parameter = Parameter {
            name: "",
            default: 1.0 / 3.0,
            accepts: Accepts::Finite,
        };
        const BOX: &[Parameter] = &[radius(0.5)];
        const TENT: &[Parameter] = &[radius(1.0)];
        const GAUSSIAN: &[Parameter] = &[
            radius(1.5),
            Parameter {
                name: "sigma",
                default: 0.5,
                accepts: Accepts::Positive,
            },
        ];
        const MITCHELL: &[Parameter] = &[
            radius(2.0),
            Parameter { name: "b", ..THIRD },
            Parameter { name: "c", ..THIRD },
        ];
        match self {
            FilterKind::Box => BOX,
            FilterKind::Tent => TENT,
            FilterKind::Gaussian => GAUSSIAN,
            FilterKind::Mitchell => MITCHELL,
        }
    }
}

impl From<FilterKind> for Filter {
    /// The filter of that kind with the defaults of
    /// [`FilterKind::parameters`].
    fn from(kind: FilterKind) -> Self {
        let defaults: Vec<f32> = kind.parameters().iter().map(|p| p.default).collect();
        Filter::with_parameters(kind, &defaults)
    }
}

impl Default for Filter {
    fn default() -> Self {
        FilterKind::Gaussian.into()
    }
}

impl Filter {
    /// The filter of `kind` with `values`, one for each of
    /// [`FilterKind::parameters`] in its order, each accepted by its
    /// [`Parameter::check`].
    pub fn with_parameters(kind: FilterKind, values: &[f32]) -> Self {
        match (kind, values) {
            (FilterKind::Box, &[radius]) => Filter::Box { radius },
            (FilterKind::Tent, &[radius]) => Filter::Tent { radius },
            (FilterKind::Gaussian, &[radius, sigma]) => Filter::Gaussian { radius, sigma },
            (FilterKind::Mitchell, &[radius, b, c]) => Filter::Mitchell { radius, b, c },
            _ => panic!(
                "the {kind} filter takes {} values, not {}",
                kind.parameters().len(),
                values.len()
            ),
        }
    }

    /// The filter called `name`, with its default parameters.
    pub fn named(name: &str) -> Result<Self, crate::names::UnknownName> {
        FilterKind::from_name(name).map(Self::from)
    }

    /// The filter's name (its kind's, from the one name table).
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// Which filter this is, without its parameters.
    pub fn kind(&self) -> FilterKind {
        match self {
            Filter::Box { .. } => FilterKind::Box,
            Filter::Tent { .. } => FilterKind::Tent,
            Filter::Gaussian { .. } => FilterKind::Gaussian,
            Filter::Mitchell { .. } => FilterKind::Mitchell,
        }
    }

    /// Half width of the support in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            Filter::Box { radius }
            | Filter::Tent { radius }
            | Filter::Gaussian { radius, .. }
            | Filter::Mitchell { radius, .. } => radius,
        }
    }

    /// The filter weight of a sample at offset `(dx, dy)` from a pixel
    /// centre.
    #[inline]
    pub fn eval(&self, dx: f32, dy: f32) -> f32 {
        self.eval_1d(dx) * self.eval_1d(dy)
    }

    /// One factor of the separable filter.
    #[inline]
    pub fn eval_1d(&self, x: f32) -> f32 {
        let x = x.abs();
        match *self {
            Filter::Box { radius } => {
                if x < radius {
                    1.0
                } else {
                    0.0
                }
            }
            Filter::Tent { radius } => (1.0 - x / radius).max(0.0),
            Filter::Gaussian { radius, sigma } => {
                if x >= radius {
                    return 0.0;
                }
                let g = |v: f32| (-v * v / (2.0 * sigma * sigma)).exp();
                (g(x) - g(radius)).max(0.0)
            }
            Filter::Mitchell { radius, b, c } => {
                if x >= radius {
                    return 0.0;
                }
                // The cubic is defined on [0, 2]; rescale the support.
                let x = 2.0 * x / radius;
                if x < 1.0 {
                    ((12.0 - 9.0 * b - 6.0 * c) * x * x * x
                        + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                        + (6.0 - 2.0 * b))
                        / 6.0
                } else {
                    ((-b - 6.0 * c) * x * x * x
                        + (6.0 * b + 30.0 * c) * x * x
                        + (-12.0 * b - 48.0 * c) * x
                        + (8.0 * b + 24.0 * c))
                        / 6.0
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_is_built_from_its_parameter_list() {
        for &kind in FilterKind::ALL {
            let parameters = kind.parameters();
            assert_eq!(parameters[0].name, "radius", "{kind}");
            let defaults: Vec<f32> = parameters.iter().map(|p| p.default).collect();
            let filter = Filter::with_parameters(kind, &defaults);
            assert_eq!((filter.kind(), filter.radius()), (kind, defaults[0]));
            assert_eq!(filter, Filter::from(kind));
            for (i, p) in parameters.iter().enumerate() {
                assert!(p.check(p.default).is_ok(), "{kind} {}", p.name);
                assert!(!parameters[..i].iter().any(|q| q.name == p.name));
            }
        }
        assert_eq!(
            Filter::from(FilterKind::Mitchell),
            Filter::Mitchell {
                radius: 2.0,
                b: 1.0 / 3.0,
                c: 1.0 / 3.0
            }
        );
        let radius = FilterKind::Box.parameters()[0];
        assert_eq!(
            radius.check(0.0),
            Err("`radius` is 0 but must be greater than 0".into())
        );
        assert!(radius.check(f32::NAN).is_err());
    }

    #[test]
    fn mitchell_integrates_to_one_and_vanishes_at_the_edge() {
        let f = Filter::from(FilterKind::Mitchell);
        let n = 4000;
        let sum: f32 = (0..n)
            .map(|i| f.eval_1d(-2.0 + 4.0 * (i as f32 + 0.5) / n as f32) * 4.0 / n as f32)
            .sum();
        assert!((sum - 1.0).abs() < 1e-3, "{sum}");
        assert!(f.eval_1d(2.0).abs() < 1e-6);
        assert!(f.eval_1d(1.5) < 0.0);
    }

    #[test]
    fn gaussian_and_tent_reach_zero_at_radius() {
        assert_eq!(Filter::default().eval(1.5, 0.0), 0.0);
        assert_eq!(Filter::from(FilterKind::Tent).eval(0.0, 1.0), 0.0);
        assert_eq!(Filter::from(FilterKind::Box).eval(0.49, -0.49), 1.0);
    }
}
