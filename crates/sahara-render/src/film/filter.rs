//! Pixel reconstruction filters (separable, evaluated in pixel units).

use glam::Vec4;

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

    /// The values of its kind's [`FilterKind::parameters`], in order.
    pub fn parameters(&self) -> Vec<f32> {
        match *self {
            Filter::Box { radius } | Filter::Tent { radius } => vec![radius],
            Filter::Gaussian { radius, sigma } => vec![radius, sigma],
            Filter::Mitchell { radius, b, c } => vec![radius, b, c],
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
        match *self {
            Filter::Box { radius } => BoxKernel { radius }.eval(x),
            Filter::Tent { radius } => TentKernel { radius }.eval(x),
            Filter::Gaussian { radius, sigma } => GaussianKernel::new(radius, sigma).eval(x),
            Filter::Mitchell { radius, b, c } => MitchellKernel { radius, b, c }.eval(x),
        }
    }
}

/// One factor of a separable filter, with what it needs computed once:
/// the film's splats are monomorphised over it, so that a sample's taps
/// are weighed inline with no dispatch on the filter's kind. Each kind
/// gives the same bits as [`Filter::eval_1d`], which calls it.
pub(crate) trait Kernel: Copy {
    /// True when [`Kernel::eval`] calls nothing (no `exp`): weighing a few
    /// columns more than a sample needs then costs less than choosing how
    /// many, and the weights vectorise.
    const PLAIN: bool;

    /// The weight at offset `x` (pixels) from a pixel centre, without
    /// branches on `x` where the kind allows (a splat's offsets are
    /// unpredictable, and a mispredicted branch costs more than the other
    /// side's arithmetic).
    fn eval(&self, x: f32) -> f32;

    /// [`Kernel::eval`] of four offsets: the same operations lane by lane,
    /// so the same bits, in one vector where the kind allows.
    #[inline(always)]
    fn eval4(&self, x: Vec4) -> Vec4 {
        Vec4::new(
            self.eval(x.x),
            self.eval(x.y),
            self.eval(x.z),
            self.eval(x.w),
        )
    }
}

/// [`Filter::Box`]'s factor.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxKernel {
    pub radius: f32,
}

impl Kernel for BoxKernel {
    const PLAIN: bool = true;

    #[inline(always)]
    fn eval(&self, x: f32) -> f32 {
        if x.abs() < self.radius {
            1.0
        } else {
            0.0
        }
    }

    #[inline(always)]
    fn eval4(&self, x: Vec4) -> Vec4 {
        Vec4::select(
            x.abs().cmplt(Vec4::splat(self.radius)),
            Vec4::ONE,
            Vec4::ZERO,
        )
    }
}

/// [`Filter::Tent`]'s factor.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TentKernel {
    pub radius: f32,
}

impl Kernel for TentKernel {
    const PLAIN: bool = true;

    #[inline(always)]
    fn eval(&self, x: f32) -> f32 {
        (1.0 - x.abs() / self.radius).max(0.0)
    }

    #[inline(always)]
    fn eval4(&self, x: Vec4) -> Vec4 {
        (Vec4::ONE - x.abs() / self.radius).max(Vec4::ZERO)
    }
}

/// [`Filter::Gaussian`]'s factor, with its value at the radius computed
/// once rather than at every tap.
#[derive(Clone, Copy, Debug)]
pub(crate) struct GaussianKernel {
    radius: f32,
    /// `2 sigma^2`.
    two_sigma2: f32,
    /// The Gaussian at the radius, subtracted so the filter reaches zero.
    at_radius: f32,
}

impl GaussianKernel {
    /// The factor of a Gaussian of standard deviation `sigma` cut at `radius`.
    pub fn new(radius: f32, sigma: f32) -> Self {
        let two_sigma2 = 2.0 * sigma * sigma;
        Self {
            radius,
            two_sigma2,
            at_radius: gaussian(radius, two_sigma2),
        }
    }
}

/// `exp(-v^2 / (2 sigma^2))`.
#[inline(always)]
fn gaussian(v: f32, two_sigma2: f32) -> f32 {
    (-v * v / two_sigma2).exp()
}

impl Kernel for GaussianKernel {
    const PLAIN: bool = false;

    #[inline(always)]
    fn eval(&self, x: f32) -> f32 {
        let x = x.abs();
        if x >= self.radius {
            return 0.0;
        }
        (gaussian(x, self.two_sigma2) - self.at_radius).max(0.0)
    }
}

/// [`Filter::Mitchell`]'s factor.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MitchellKernel {
    pub radius: f32,
    pub b: f32,
    pub c: f32,
}

impl Kernel for MitchellKernel {
    const PLAIN: bool = true;

    #[inline(always)]
    fn eval(&self, x: f32) -> f32 {
        let (radius, b, c) = (self.radius, self.b, self.c);
        let x = x.abs();
        // The cubic is defined on [0, 2]; rescale the support. Both
        // pieces' numerators are computed and one is chosen before the one
        // division, so that the choice is a cheap select, not a branch.
        let t = 2.0 * x / radius;
        let near = (12.0 - 9.0 * b - 6.0 * c) * t * t * t
            + (-18.0 + 12.0 * b + 6.0 * c) * t * t
            + (6.0 - 2.0 * b);
        let far = (-b - 6.0 * c) * t * t * t
            + (6.0 * b + 30.0 * c) * t * t
            + (-12.0 * b - 48.0 * c) * t
            + (8.0 * b + 24.0 * c);
        let v = if t < 1.0 { near } else { far } / 6.0;
        if x >= radius {
            0.0
        } else {
            v
        }
    }

    #[inline(always)]
    fn eval4(&self, x: Vec4) -> Vec4 {
        let (radius, b, c) = (self.radius, self.b, self.c);
        let x = x.abs();
        let t = 2.0 * x / radius;
        let near = (12.0 - 9.0 * b - 6.0 * c) * t * t * t
            + (-18.0 + 12.0 * b + 6.0 * c) * t * t
            + (6.0 - 2.0 * b);
        let far = (-b - 6.0 * c) * t * t * t
            + (6.0 * b + 30.0 * c) * t * t
            + (-12.0 * b - 48.0 * c) * t
            + (8.0 * b + 24.0 * c);
        let v = Vec4::select(t.cmplt(Vec4::ONE), near, far) / 6.0;
        Vec4::select(x.cmpge(Vec4::splat(radius)), Vec4::ZERO, v)
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
            assert_eq!(filter.parameters(), defaults, "{kind}");
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
    fn every_kernel_weighs_four_offsets_as_it_weighs_one() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for filter in [
            Filter::Box { radius: 0.5 },
            Filter::Box { radius: 1.3 },
            Filter::Tent { radius: 1.0 },
            Filter::Tent { radius: 2.7 },
            Filter::Mitchell {
                radius: 2.0,
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
            Filter::Mitchell {
                radius: 3.1,
                b: -0.4,
                c: 0.9,
            },
        ] {
            for i in 0..4000 {
                // Offsets across and beyond the support, and the edges.
                let r = filter.radius();
                let x = match i % 8 {
                    0 => r,
                    1 => -r,
                    2 => 0.5 * r,
                    _ => (next() - 0.5) * 3.0 * r,
                };
                let xs = Vec4::new(x, -x, x * 0.5 + next(), next() - 0.5);
                let kernel = |v: Vec4| match filter {
                    Filter::Box { radius } => BoxKernel { radius }.eval4(v),
                    Filter::Tent { radius } => TentKernel { radius }.eval4(v),
                    Filter::Mitchell { radius, b, c } => MitchellKernel { radius, b, c }.eval4(v),
                    Filter::Gaussian { .. } => unreachable!(),
                };
                let four = kernel(xs).to_array();
                for (lane, &x) in xs.to_array().iter().enumerate() {
                    assert_eq!(
                        four[lane].to_bits(),
                        filter.eval_1d(x).to_bits(),
                        "{filter:?} at {x}"
                    );
                }
            }
        }
    }

    #[test]
    fn gaussian_and_tent_reach_zero_at_radius() {
        assert_eq!(Filter::default().eval(1.5, 0.0), 0.0);
        assert_eq!(Filter::from(FilterKind::Tent).eval(0.0, 1.0), 0.0);
        assert_eq!(Filter::from(FilterKind::Box).eval(0.49, -0.49), 1.0);
    }
}
