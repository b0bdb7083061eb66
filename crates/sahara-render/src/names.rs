//! The names of the settings a user picks by name: integrator, sampler,
//! filter, tone map and shape kind. Each setting has one name table, here
//! beside the type it names; the command line, the scene file and every
//! scene reader parse and print names through it, so adding a setting is a
//! change in this crate only.

use std::fmt;

/// A setting chosen by name from a fixed list.
pub trait Named: Copy + Sized + 'static {
    /// What the setting is called in messages (`"integrator"`).
    const WHAT: &'static str;
    /// Every value, in the order messages and documents list them.
    const ALL: &'static [Self];
    /// Other names files may use for a value (`glossy` for `conductor`),
    /// read but never written.
    const ALIASES: &'static [(&'static str, Self)] = &[];

    /// The value's name, as written in files and on the command line.
    fn name(self) -> &'static str;

    /// The value called `name` (exact, lower case).
    fn from_name(name: &str) -> Result<Self, UnknownName> {
        Self::ALL
            .iter()
            .copied()
            .find(|v| v.name() == name)
            .or_else(|| {
                Self::ALIASES
                    .iter()
                    .find(|(alias, _)| *alias == name)
                    .map(|(_, v)| *v)
            })
            .ok_or_else(|| UnknownName {
                what: Self::WHAT,
                name: name.to_owned(),
                expected: Self::ALL.iter().map(|v| v.name()).collect(),
            })
    }

    /// Every value's name, in the order of [`Named::ALL`].
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|v| v.name()).collect()
    }
}

/// A number a setting takes by name (a filter's `radius`): its default and
/// the values it accepts. Readers of scene files take a setting's
/// parameters from its list, so a new setting needs no change there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameter {
    /// Its name in files.
    pub name: &'static str,
    /// Its value when not given.
    pub default: f32,
    /// The values it takes.
    pub accepts: Accepts,
}

/// The values a [`Parameter`] takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Accepts {
    /// Any finite number.
    Finite,
    /// A number greater than 0.
    Positive,
    /// A finite number of at least this.
    AtLeast(f32),
    /// A whole number of at least this (and at most 2^24, which `f32`
    /// holds exactly).
    WholeAtLeast(u32),
    /// A finite number greater than this.
    Above(f32),
    /// A finite number from the first to the second, both included.
    Between(f32, f32),
}

impl Accepts {
    /// True if `value` is accepted.
    pub fn takes(self, value: f32) -> bool {
        const WHOLE_MAX: f32 = (1 << 24) as f32;
        match self {
            Accepts::Finite => value.is_finite(),
            Accepts::Positive => value.is_finite() && value > 0.0,
            Accepts::AtLeast(m) => value.is_finite() && value >= m,
            Accepts::WholeAtLeast(m) => {
                value.fract() == 0.0 && value >= m as f32 && value <= WHOLE_MAX
            }
            Accepts::Above(m) => value.is_finite() && value > m,
            Accepts::Between(lo, hi) => value.is_finite() && (lo..=hi).contains(&value),
        }
    }

    /// What an accepted value is, after "must be" (`greater than 0`).
    pub fn must(self) -> String {
        match self {
            Accepts::Finite => "finite".to_string(),
            Accepts::Positive => "greater than 0".to_string(),
            Accepts::AtLeast(m) => format!("at least {m}"),
            Accepts::WholeAtLeast(m) => format!("a whole number of at least {m}"),
            Accepts::Above(m) => format!("greater than {m}"),
            Accepts::Between(lo, hi) => format!("between {lo} and {hi}"),
        }
    }
}

impl Parameter {
    /// True if the parameter takes whole numbers only.
    pub fn is_whole(&self) -> bool {
        matches!(self.accepts, Accepts::WholeAtLeast(_))
    }

    /// `value` if the parameter accepts it, else why not (one line).
    pub fn check(&self, value: f32) -> Result<f32, String> {
        if self.accepts.takes(value) {
            Ok(value)
        } else {
            Err(format!(
                "`{}` is {value} but must be {}",
                self.name,
                self.accepts.must()
            ))
        }
    }
}

/// A name that is not in a setting's table.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownName {
    /// What the setting is called (`"filter"`).
    pub what: &'static str,
    /// The name given.
    pub name: String,
    /// The names the setting has.
    pub expected: Vec<&'static str>,
}

impl fmt::Display for UnknownName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "unknown {} '{}'; expected {}",
            self.what,
            self.name,
            one_of(&self.expected)
        )
    }
}

impl std::error::Error for UnknownName {}

/// `"a, b or c"`.
pub fn one_of(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => (*one).to_owned(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    }
}

/// Implements [`Named`], `FromStr` and `Display` for a type from its one
/// table of `value => "name"` pairs (and, optionally, `aliases { "other"
/// => value }`).
macro_rules! name_table {
    ($ty:ty, $what:literal, { $($value:path => $name:literal),+ $(,)? }
     $(, aliases { $($alias:literal => $avalue:path),* $(,)? })?) => {
        impl $crate::names::Named for $ty {
            const WHAT: &'static str = $what;
            const ALL: &'static [Self] = &[$($value),+];
            const ALIASES: &'static [(&'static str, Self)] = &[$($(($alias, $avalue)),*)?];

            fn name(self) -> &'static str {
                match self {
                    $($value => $name,)+
                }
            }
        }

        impl std::str::FromStr for $ty {
            type Err = $crate::names::UnknownName;

            fn from_str(s: &str) -> Result<Self, Self::Err> {
                <Self as $crate::names::Named>::from_name(s)
            }
        }

        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str($crate::names::Named::name(*self))
            }
        }
    };
}
pub(crate) use name_table;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FilterKind, IntegratorKind, SamplerKind, ShapeKind, ToneMap};

    fn round_trips<T: Named + PartialEq + fmt::Debug + std::str::FromStr>() {
        let names = T::names();
        for (i, v) in T::ALL.iter().enumerate() {
            assert_eq!(T::from_name(v.name()), Ok(*v));
            assert!(!names[..i].contains(&v.name()), "{} twice", v.name());
        }
        let e = T::from_name("no-such-name").unwrap_err().to_string();
        assert!(e.starts_with(&format!("unknown {} 'no-such-name'; expected ", T::WHAT)));
        assert!(
            e.ends_with(&format!(" or {}", names.last().unwrap())),
            "{e}"
        );
    }

    #[test]
    fn every_table_round_trips_and_names_its_values_in_errors() {
        round_trips::<IntegratorKind>();
        round_trips::<SamplerKind>();
        round_trips::<FilterKind>();
        round_trips::<ToneMap>();
        round_trips::<ShapeKind>();
        assert_eq!(
            IntegratorKind::from_name("whitted")
                .unwrap_err()
                .to_string(),
            "unknown integrator 'whitted'; expected path, distribution, bdpt, lightpath, sppm, normals, depth, ao or cost"
        );
    }

    #[test]
    fn one_of_joins_names() {
        assert_eq!(one_of(&["a"]), "a");
        assert_eq!(one_of(&["a", "b"]), "a or b");
        assert_eq!(one_of(&["a", "b", "c"]), "a, b or c");
    }
}
