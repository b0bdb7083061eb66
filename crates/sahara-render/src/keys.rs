//! Kinds described by their keys: a material kind or a light kind lists
//! the values it takes ([`Key`]: name, type, default, accepted range,
//! whether a texture may multiply it) and builds itself from the values a
//! file gave ([`Values`]). Readers of scene files check a file's keys
//! against the list and report what is wrong in its terms, so a new kind
//! or key needs no change there.

use glam::Vec3;

use crate::names::{one_of, Accepts};

/// A value a kind takes, by name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key {
    /// Its name in files.
    pub name: &'static str,
    /// What it is and the values it takes.
    pub ty: KeyType,
    /// Its value when not given.
    pub default: Fallback,
    /// True if a texture may multiply it (at most one key of a kind).
    pub textured: bool,
    /// What it means, in a few words (for documents and messages).
    pub about: &'static str,
}

/// What a [`Key`]'s value is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KeyType {
    /// A number.
    Number(Accepts),
    /// A colour: three numbers, each accepted.
    Colour(Accepts),
    /// A position: three finite numbers.
    Point,
    /// A direction: three finite numbers, not all zero.
    Direction,
    /// True or false.
    Flag,
    /// One of these names.
    Choice(&'static [&'static str]),
    /// The name of another entry of the file (a material's, say).
    Reference,
}

/// The value of a [`Key`] that is not given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fallback {
    /// None: the key must be given.
    Required,
    /// None: the kind does without it (or takes another key's value).
    Absent,
    /// This number.
    Number(f32),
    /// This colour or position.
    Triple([f32; 3]),
    /// This truth value.
    Flag(bool),
    /// This name.
    Choice(&'static str),
}

/// A value given for a [`Key`].
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number.
    Number(f32),
    /// Three numbers.
    Triple(Vec3),
    /// True or false.
    Flag(bool),
    /// A name.
    Name(String),
}

/// What is wrong with the values given to a kind: the key at fault (none
/// for the entry as a whole) and why, in one line that names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyError {
    /// The key the error is about, if one.
    pub key: Option<&'static str>,
    /// Why.
    pub message: String,
}

impl KeyError {
    /// An error about `key`.
    pub fn at(key: &'static str, message: impl Into<String>) -> Self {
        Self {
            key: Some(key),
            message: message.into(),
        }
    }

    /// An error about the entry as a whole.
    pub fn entry(message: impl Into<String>) -> Self {
        Self {
            key: None,
            message: message.into(),
        }
    }
}

impl Key {
    /// `value` if this key takes it, else why not (one line naming the
    /// key).
    pub fn check(&self, value: Value) -> Result<Value, String> {
        let name = self.name;
        let wrong = |what: &str| format!("`{name}` must be {what}");
        match (self.ty, &value) {
            (KeyType::Number(accepts), Value::Number(x)) => {
                if accepts.takes(*x) {
                    Ok(value)
                } else {
                    Err(format!("`{name}` is {x} but must be {}", accepts.must()))
                }
            }
            (KeyType::Number(_), _) => Err(wrong("a number")),
            (KeyType::Colour(accepts), Value::Triple(v)) => {
                if v.to_array().iter().all(|&c| accepts.takes(c)) {
                    Ok(value)
                } else if !v.is_finite() {
                    Err(format!("`{name}` must be finite, not {v}"))
                } else if accepts == Accepts::AtLeast(0.0) {
                    Err(format!("`{name}` {v} must not be negative"))
                } else {
                    Err(format!(
                        "`{name}` {v} must have every component {}",
                        accepts.must()
                    ))
                }
            }
            (KeyType::Point, Value::Triple(v)) => {
                if v.is_finite() {
                    Ok(value)
                } else {
                    Err(format!("`{name}` must be finite, not {v}"))
                }
            }
            (KeyType::Direction, Value::Triple(v)) => {
                if v.is_finite() && v.length_squared() > 0.0 && v.length_squared().is_finite() {
                    Ok(value)
                } else {
                    Err(format!("`{name}` must be a non-zero direction"))
                }
            }
            (KeyType::Colour(_) | KeyType::Point | KeyType::Direction, _) => {
                Err(wrong("three numbers"))
            }
            (KeyType::Flag, Value::Flag(_)) => Ok(value),
            (KeyType::Flag, _) => Err(format!("`{name}`: expected true or false")),
            (KeyType::Choice(names), Value::Name(n)) => {
                if names.contains(&n.as_str()) {
                    Ok(value)
                } else {
                    Err(format!("`{name}` is '{n}'; expected {}", one_of(names)))
                }
            }
            (KeyType::Reference, Value::Name(_)) => Ok(value),
            (KeyType::Choice(_) | KeyType::Reference, _) => Err(wrong("a string")),
        }
    }

    /// The default as written in a document (`0.5`, `[1, 1, 1]`,
    /// `required`, or empty when absent).
    pub fn default_text(&self) -> String {
        match self.default {
            Fallback::Required => "required".to_string(),
            Fallback::Absent => String::new(),
            Fallback::Number(x) => format!("{x}"),
            Fallback::Triple([a, b, c]) => format!("[{a}, {b}, {c}]"),
            Fallback::Flag(b) => format!("{b}"),
            Fallback::Choice(n) => format!("\"{n}\""),
        }
    }

    /// The values taken, as written in a document.
    pub fn type_text(&self) -> String {
        match self.ty {
            KeyType::Number(a) => format!("number, {}", a.must()),
            KeyType::Colour(Accepts::AtLeast(0.0)) => "colour, not negative".into(),
            KeyType::Colour(a) => format!("colour, each component {}", a.must()),
            KeyType::Point => "point".into(),
            KeyType::Direction => "direction, not zero".into(),
            KeyType::Flag => "true or false".into(),
            KeyType::Choice(names) => names
                .iter()
                .map(|n| format!("\"{n}\""))
                .collect::<Vec<_>>()
                .join(" \\| "),
            KeyType::Reference => "a material's name".into(),
        }
    }
}

/// The values given to a kind, each checked by its [`Key`], read with the
/// keys' defaults where not given.
#[derive(Clone, Debug, PartialEq)]
pub struct Values {
    keys: &'static [Key],
    given: Vec<Option<Value>>,
}

impl Values {
    /// No values given to a kind of these keys.
    pub fn new(keys: &'static [Key]) -> Self {
        Self {
            keys,
            given: vec![None; keys.len()],
        }
    }

    /// The keys the values are for.
    pub fn keys(&self) -> &'static [Key] {
        self.keys
    }

    /// Gives `name` the value `value`: an error (one line) if the kind has
    /// no such key or the key does not take the value.
    pub fn set(&mut self, name: &str, value: Value) -> Result<(), String> {
        let i = self
            .keys
            .iter()
            .position(|k| k.name == name)
            .ok_or_else(|| format!("no key `{name}`"))?;
        self.given[i] = Some(self.keys[i].check(value)?);
        Ok(())
    }

    /// The first key that must be given and is not.
    pub fn missing(&self) -> Option<&'static str> {
        self.keys
            .iter()
            .zip(&self.given)
            .find(|(k, v)| k.default == Fallback::Required && v.is_none())
            .map(|(k, _)| k.name)
    }

    fn index(&self, name: &str) -> usize {
        self.keys
            .iter()
            .position(|k| k.name == name)
            .unwrap_or_else(|| panic!("a kind reads `{name}`, which it does not list"))
    }

    /// True if `name` was given.
    pub fn is_given(&self, name: &str) -> bool {
        self.given[self.index(name)].is_some()
    }

    fn value(&self, name: &str) -> (Option<&Value>, Fallback) {
        let i = self.index(name);
        (self.given[i].as_ref(), self.keys[i].default)
    }

    /// The number `name`, given or its default (`None` if neither).
    pub fn number(&self, name: &str) -> Option<f32> {
        match self.value(name) {
            (Some(Value::Number(x)), _) => Some(*x),
            (_, Fallback::Number(x)) => Some(x),
            _ => None,
        }
    }

    /// The three numbers `name`, given or its default (`None` if
    /// neither).
    pub fn triple(&self, name: &str) -> Option<Vec3> {
        match self.value(name) {
            (Some(Value::Triple(v)), _) => Some(*v),
            (_, Fallback::Triple(v)) => Some(Vec3::from_array(v)),
            _ => None,
        }
    }

    /// The truth value `name`, given or its default (false if neither).
    pub fn flag(&self, name: &str) -> bool {
        match self.value(name) {
            (Some(Value::Flag(b)), _) => *b,
            (_, Fallback::Flag(b)) => b,
            _ => false,
        }
    }

    /// The name `name`, given or its default (`None` if neither).
    pub fn name(&self, name: &str) -> Option<&str> {
        match self.value(name) {
            (Some(Value::Name(n)), _) => Some(n),
            (_, Fallback::Choice(n)) => Some(n),
            _ => None,
        }
    }
}

impl Values {
    /// [`Values::number`] of a key the kind lists with a default (or
    /// has checked is given).
    pub fn number_of(&self, name: &str) -> f32 {
        self.number(name)
            .unwrap_or_else(|| panic!("`{name}` has no value"))
    }

    /// [`Values::triple`] of a key the kind lists with a default (or has
    /// checked is given).
    pub fn triple_of(&self, name: &str) -> Vec3 {
        self.triple(name)
            .unwrap_or_else(|| panic!("`{name}` has no value"))
    }

    /// [`Values::name`] of a key the kind lists with a default (or has
    /// checked is given).
    pub fn name_of(&self, name: &str) -> &str {
        self.name(name)
            .unwrap_or_else(|| panic!("`{name}` has no value"))
    }
}

/// A kind's keys: the number `name` with a default and the values it
/// takes (for the tables of kinds).
pub(crate) const fn number(
    name: &'static str,
    default: f32,
    accepts: Accepts,
    about: &'static str,
) -> Key {
    Key {
        name,
        ty: KeyType::Number(accepts),
        default: Fallback::Number(default),
        textured: false,
        about,
    }
}

/// A colour key with every component in `[0, 1]` (a reflectance).
pub(crate) const fn reflectance(name: &'static str, default: f32, about: &'static str) -> Key {
    Key {
        name,
        ty: KeyType::Colour(Accepts::Between(0.0, 1.0)),
        default: Fallback::Triple([default; 3]),
        textured: false,
        about,
    }
}

/// A colour key with no negative component that must be given (a
/// radiance, an intensity).
pub(crate) const fn power(name: &'static str, about: &'static str) -> Key {
    Key {
        name,
        ty: KeyType::Colour(Accepts::AtLeast(0.0)),
        default: Fallback::Required,
        textured: false,
        about,
    }
}

/// A truth-value key.
pub(crate) const fn flag(name: &'static str, default: bool, about: &'static str) -> Key {
    Key {
        name,
        ty: KeyType::Flag,
        default: Fallback::Flag(default),
        textured: false,
        about,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const KEYS: &[Key] = &[
        number("roughness", 0.2, Accepts::Between(0.0, 1.0), "roughness"),
        reflectance("albedo", 0.5, "reflectance"),
        power("radiance", "emitted radiance"),
        Key {
            name: "distribution",
            ty: KeyType::Choice(&["ggx", "beckmann"]),
            default: Fallback::Choice("ggx"),
            textured: false,
            about: "",
        },
    ];

    #[test]
    fn values_are_checked_and_read_with_defaults() {
        let mut v = Values::new(KEYS);
        assert_eq!(v.missing(), Some("radiance"));
        assert_eq!(v.number("roughness"), Some(0.2));
        assert_eq!(v.triple("albedo"), Some(Vec3::splat(0.5)));
        assert_eq!(v.name("distribution"), Some("ggx"));
        v.set("roughness", Value::Number(0.4)).unwrap();
        v.set("radiance", Value::Triple(Vec3::ONE)).unwrap();
        assert_eq!(v.missing(), None);
        assert_eq!(v.number("roughness"), Some(0.4));
        assert!(v.is_given("radiance") && !v.is_given("albedo"));
        let e = |k: &str, x: Value| v.clone().set(k, x).unwrap_err();
        assert_eq!(
            e("roughness", Value::Number(2.0)),
            "`roughness` is 2 but must be between 0 and 1"
        );
        assert_eq!(
            e("albedo", Value::Triple(Vec3::new(0.5, 1.5, 0.0))),
            "`albedo` [0.5, 1.5, 0] must have every component between 0 and 1"
        );
        assert_eq!(
            e("radiance", Value::Triple(Vec3::new(-1.0, 1.0, 1.0))),
            "`radiance` [-1, 1, 1] must not be negative"
        );
        assert_eq!(
            e("distribution", Value::Name("phong".into())),
            "`distribution` is 'phong'; expected ggx or beckmann"
        );
        assert_eq!(
            e("roughness", Value::Flag(true)),
            "`roughness` must be a number"
        );
        assert_eq!(e("sheen", Value::Number(1.0)), "no key `sheen`");
    }
}
