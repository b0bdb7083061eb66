//! Typed parameter lists: `"float fov" 45`, `"rgb L" [1 1 1]`,
//! `"spectrum eta" "metal-Au-eta"`, `"texture reflectance" "wood"`.
//!
//! Every lookup checks the parameter's declared type and array length and
//! marks it used; what no lookup asked for is reported afterwards as an
//! unknown parameter.

use std::cell::Cell;

use sahara_readers::FormatError;

use crate::common::position::Loc;

/// The values of one parameter.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Values {
    /// Numbers (every numeric type).
    Num(Vec<f64>),
    /// Strings (`string`, `texture`, a named `spectrum`, or a quoted `bool`).
    Str(Vec<String>),
    /// Bare `true` / `false`.
    Bool(Vec<bool>),
}

/// The parameter types of the format, with pbrt-v3's spellings mapped to
/// pbrt-v4's (`point` → `point3`, `color` → `rgb`, ...).
pub(crate) const TYPES: &[&str] = &[
    "integer",
    "float",
    "point2",
    "vector2",
    "point3",
    "vector3",
    "normal3",
    "rgb",
    "spectrum",
    "blackbody",
    "bool",
    "string",
    "texture",
];

fn canonical_type(t: &str) -> Option<&'static str> {
    Some(match t {
        "point" => "point3",
        "vector" => "vector3",
        "normal" => "normal3",
        "color" => "rgb",
        _ => TYPES.iter().copied().find(|&k| k == t)?,
    })
}

/// One parameter.
#[derive(Clone, Debug)]
pub(crate) struct Param {
    /// Its type, canonical (see [`TYPES`]).
    pub(crate) ty: &'static str,
    /// Its name.
    pub(crate) name: String,
    /// Its values.
    pub(crate) values: Values,
    /// Where its declaration starts.
    pub(crate) loc: Loc,
    used: Cell<bool>,
}

impl Param {
    /// A parameter from its `"type name"` declaration at `loc` and its values.
    pub(crate) fn new(decl: &str, values: Values, loc: Loc) -> Result<Param, FormatError> {
        let mut words = decl.split_whitespace();
        let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
            return Err(loc.error(format!(
                "expected a parameter declaration \"type name\", found \"{decl}\""
            )));
        };
        let canonical = canonical_type(ty)
            .ok_or_else(|| loc.error(format!("unknown parameter type '{ty}' (of \"{decl}\")")))?;
        let p = Param {
            ty: canonical,
            name: name.to_owned(),
            values,
            loc,
            used: Cell::new(false),
        };
        p.check_values()?;
        Ok(p)
    }

    fn check_values(&self) -> Result<(), FormatError> {
        let ok = match (&self.values, self.ty) {
            (Values::Num(_), "string" | "texture" | "bool") => false,
            (Values::Num(v), "integer") => v.iter().all(|x| x.fract() == 0.0),
            (Values::Num(_), _) => true,
            (Values::Str(_), "string" | "texture" | "spectrum") => true,
            (Values::Str(v), "bool") => v.iter().all(|s| s == "true" || s == "false"),
            (Values::Str(_), _) => false,
            (Values::Bool(_), t) => t == "bool",
        };
        if !ok {
            let what = match (&self.values, self.ty) {
                (Values::Num(_), "integer") => "whole numbers",
                (_, "string" | "texture") => "quoted strings",
                (_, "bool") => "true or false",
                (_, "spectrum") => "numbers or one quoted name",
                _ => "numbers",
            };
            return Err(self.loc.error(format!(
                "parameter \"{} {}\" takes {what}",
                self.ty, self.name
            )));
        }
        Ok(())
    }

    fn len(&self) -> usize {
        match &self.values {
            Values::Num(v) => v.len(),
            Values::Str(v) => v.len(),
            Values::Bool(v) => v.len(),
        }
    }

    /// An error about this parameter.
    pub(crate) fn error(&self, message: impl std::fmt::Display) -> FormatError {
        self.loc.error(format!(
            "parameter \"{} {}\": {message}",
            self.ty, self.name
        ))
    }

    /// Numbers, if the values are numbers.
    pub(crate) fn nums(&self) -> Option<&[f64]> {
        match &self.values {
            Values::Num(v) => Some(v),
            _ => None,
        }
    }
}

/// A spectrum-valued parameter as written.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum SpectrumParam {
    /// `rgb`.
    Rgb([f64; 3]),
    /// `blackbody`: temperature in kelvin (pbrt-v3's second value, a scale, folded in).
    Blackbody(f64, f64),
    /// `spectrum` as wavelength-value pairs.
    Sampled(Vec<(f64, f64)>),
    /// `spectrum` by name (a named spectrum or a file), with where it was given.
    Named(String, Loc),
    /// `texture`: a texture's name.
    Texture(String),
}

/// The parameters of one directive, and the attribute defaults that apply to it.
#[derive(Clone, Debug, Default)]
pub(crate) struct ParamList {
    params: Vec<Param>,
}

impl ParamList {
    /// A list; a name given twice is an error.
    pub(crate) fn new(params: Vec<Param>) -> Result<Self, FormatError> {
        for (i, p) in params.iter().enumerate() {
            if params[..i].iter().any(|q| q.name == p.name) {
                return Err(p.loc.error(format!("parameter '{}' given twice", p.name)));
            }
        }
        Ok(Self { params })
    }

    /// This list with `defaults` appended where it does not name them
    /// itself (`Attribute` defaults).
    pub(crate) fn with_defaults(mut self, defaults: &[Param]) -> Self {
        for d in defaults {
            if !self.params.iter().any(|p| p.name == d.name) {
                self.params.push(d.clone());
            }
        }
        self
    }

    /// The parameter called `name`, marked used.
    pub(crate) fn get(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// True if the list names `name` (not marked used).
    pub(crate) fn has(&self, name: &str) -> bool {
        self.params.iter().any(|p| p.name == name)
    }

    /// Marks every parameter as read (for a directive that is skipped or
    /// replaced as a whole and warned about once).
    pub(crate) fn mark_all_used(&self) {
        for p in &self.params {
            p.used.set(true);
        }
    }

    /// Parameters no lookup asked for.
    pub(crate) fn unused(&self) -> impl Iterator<Item = &Param> {
        self.params.iter().filter(|p| !p.used.get())
    }

    fn typed(&self, name: &str, types: &[&str]) -> Result<Option<&Param>, FormatError> {
        match self.get(name) {
            Some(p) if !types.contains(&p.ty) => {
                Err(p.error(format!("expected type {}", types.join(" or "))))
            }
            other => Ok(other),
        }
    }

    fn one_num(&self, name: &str, ty: &str) -> Result<Option<f64>, FormatError> {
        let Some(p) = self.typed(name, &[ty])? else {
            return Ok(None);
        };
        match p.nums() {
            Some([v]) => Ok(Some(*v)),
            _ => Err(p.error(format!("expected one value, found {}", p.len()))),
        }
    }

    /// A `float`, or `default`.
    pub(crate) fn float(&self, name: &str, default: f64) -> Result<f64, FormatError> {
        Ok(self.one_num(name, "float")?.unwrap_or(default))
    }

    /// A `float` if given.
    pub(crate) fn float_opt(&self, name: &str) -> Result<Option<f64>, FormatError> {
        self.one_num(name, "float")
    }

    /// An `integer`, or `default`.
    pub(crate) fn int(&self, name: &str, default: i64) -> Result<i64, FormatError> {
        Ok(self.one_num(name, "integer")?.map_or(default, |v| {
            v.clamp(i64::MIN as f64, i64::MAX as f64) as i64
        }))
    }

    /// `float` values (an array), if given.
    pub(crate) fn floats(&self, name: &str) -> Result<Option<&[f64]>, FormatError> {
        Ok(self.typed(name, &["float"])?.and_then(Param::nums))
    }

    /// `integer` values, if given.
    pub(crate) fn ints(&self, name: &str) -> Result<Option<&[f64]>, FormatError> {
        Ok(self.typed(name, &["integer"])?.and_then(Param::nums))
    }

    /// A `bool`, or `default`.
    pub(crate) fn bool(&self, name: &str, default: bool) -> Result<bool, FormatError> {
        let Some(p) = self.typed(name, &["bool"])? else {
            return Ok(default);
        };
        match &p.values {
            Values::Bool(v) if v.len() == 1 => Ok(v[0]),
            Values::Str(v) if v.len() == 1 => Ok(v[0] == "true"),
            _ => Err(p.error(format!("expected one value, found {}", p.len()))),
        }
    }

    /// A `string`, if given.
    pub(crate) fn string(&self, name: &str) -> Result<Option<&str>, FormatError> {
        self.one_str(name, &["string"])
    }

    /// The strings of a `string` array, if given.
    pub(crate) fn strings(&self, name: &str) -> Result<Option<&[String]>, FormatError> {
        Ok(self
            .typed(name, &["string"])?
            .and_then(|p| match &p.values {
                Values::Str(v) => Some(&v[..]),
                _ => None,
            }))
    }

    fn one_str(&self, name: &str, types: &[&str]) -> Result<Option<&str>, FormatError> {
        let Some(p) = self.typed(name, types)? else {
            return Ok(None);
        };
        match &p.values {
            Values::Str(v) if v.len() == 1 => Ok(Some(&v[0])),
            _ => Err(p.error(format!("expected one string, found {} values", p.len()))),
        }
    }

    /// Triples (`point3`, `vector3`, `normal3`), if given; the count must be a multiple of 3.
    pub(crate) fn triples(&self, name: &str) -> Result<Option<Vec<[f64; 3]>>, FormatError> {
        self.tuples::<3>(name, &["point3", "vector3", "normal3"])
    }

    /// `rgb` triples (an array of colours, as an `rgbgrid` medium's), if given.
    pub(crate) fn rgbs(&self, name: &str) -> Result<Option<Vec<[f64; 3]>>, FormatError> {
        self.tuples::<3>(name, &["rgb"])
    }

    /// Pairs (`point2`, `vector2`, or pbrt-v3's flat `float` uv lists), if given.
    pub(crate) fn pairs(&self, name: &str) -> Result<Option<Vec<[f64; 2]>>, FormatError> {
        self.tuples::<2>(name, &["point2", "vector2", "float"])
    }

    /// One triple, or `default`.
    pub(crate) fn triple(&self, name: &str, default: [f64; 3]) -> Result<[f64; 3], FormatError> {
        match self.tuples::<3>(name, &["point3", "vector3", "normal3"])? {
            None => Ok(default),
            Some(v) if v.len() == 1 => Ok(v[0]),
            Some(v) => Err(self
                .get(name)
                .expect("present")
                .error(format!("expected one triple, found {}", v.len()))),
        }
    }

    fn tuples<const N: usize>(
        &self,
        name: &str,
        types: &[&str],
    ) -> Result<Option<Vec<[f64; N]>>, FormatError> {
        let Some(p) = self.typed(name, types)? else {
            return Ok(None);
        };
        let v = p.nums().unwrap_or(&[]);
        if v.len() % N != 0 {
            return Err(p.error(format!(
                "{} values are not a whole number of {N}-tuples",
                v.len()
            )));
        }
        Ok(Some(
            v.chunks_exact(N)
                .map(|c| std::array::from_fn(|i| c[i]))
                .collect(),
        ))
    }

    /// A spectrum-valued parameter (`rgb`, `blackbody`, `spectrum`, or a
    /// `texture` name when `textures` is allowed), if given.
    pub(crate) fn spectrum(
        &self,
        name: &str,
        textures: bool,
    ) -> Result<Option<SpectrumParam>, FormatError> {
        let types: &[&str] = if textures {
            &["rgb", "blackbody", "spectrum", "texture"]
        } else {
            &["rgb", "blackbody", "spectrum"]
        };
        let Some(p) = self.typed(name, types)? else {
            return Ok(None);
        };
        spectrum_of(p).map(Some)
    }

    /// A float-valued parameter that may be a `texture` name.
    pub(crate) fn float_or_texture(&self, name: &str) -> Result<Option<FloatParam>, FormatError> {
        let Some(p) = self.typed(name, &["float", "texture"])? else {
            return Ok(None);
        };
        match (&p.values, p.ty) {
            (Values::Num(v), _) if v.len() == 1 => Ok(Some(FloatParam::Value(v[0]))),
            (Values::Str(v), "texture") if v.len() == 1 => {
                Ok(Some(FloatParam::Texture(v[0].clone())))
            }
            _ => Err(p.error(format!("expected one value, found {}", p.len()))),
        }
    }
}

/// A float parameter as written: a value or a texture's name.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum FloatParam {
    /// A number.
    Value(f64),
    /// A float texture's name.
    Texture(String),
}

fn spectrum_of(p: &Param) -> Result<SpectrumParam, FormatError> {
    match (p.ty, &p.values) {
        ("texture", Values::Str(v)) if v.len() == 1 => Ok(SpectrumParam::Texture(v[0].clone())),
        ("rgb", Values::Num(v)) if v.len() == 3 => Ok(SpectrumParam::Rgb([v[0], v[1], v[2]])),
        ("rgb", Values::Num(v)) => Err(p.error(format!("expected 3 values, found {}", v.len()))),
        ("blackbody", Values::Num(v)) if v.len() == 1 => Ok(SpectrumParam::Blackbody(v[0], 1.0)),
        // pbrt-v3: temperature and scale.
        ("blackbody", Values::Num(v)) if v.len() == 2 => Ok(SpectrumParam::Blackbody(v[0], v[1])),
        ("blackbody", Values::Num(v)) => {
            Err(p.error(format!("expected a temperature, found {} values", v.len())))
        }
        ("spectrum", Values::Str(v)) if v.len() == 1 => {
            Ok(SpectrumParam::Named(v[0].clone(), p.loc.clone()))
        }
        ("spectrum", Values::Num(v)) if v.len() >= 2 && v.len() % 2 == 0 => {
            let pairs: Vec<(f64, f64)> = v.chunks_exact(2).map(|c| (c[0], c[1])).collect();
            if pairs.windows(2).any(|w| w[1].0 <= w[0].0) {
                return Err(p.error("wavelengths must increase"));
            }
            Ok(SpectrumParam::Sampled(pairs))
        }
        _ => Err(p.error(format!("{} values do not make a spectrum", p.len()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn loc() -> Loc {
        Loc {
            file: "t.pbrt".into(),
            line: 3,
            col: 7,
        }
    }

    fn list(items: Vec<(&str, Values)>) -> ParamList {
        ParamList::new(
            items
                .into_iter()
                .map(|(d, v)| Param::new(d, v, loc()).unwrap())
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn typed_lookups_check_type_and_length() {
        let l = list(vec![
            ("float fov", Values::Num(vec![45.0])),
            ("integer n", Values::Num(vec![1.0, 2.0])),
            ("point P", Values::Num(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0])),
            ("color Kd", Values::Num(vec![0.1, 0.2, 0.3])),
            ("bool twosided", Values::Str(vec!["true".into()])),
            ("spectrum eta", Values::Str(vec!["metal-Au-eta".into()])),
        ]);
        assert_eq!(l.float("fov", 90.0).unwrap(), 45.0);
        assert_eq!(l.float("missing", 90.0).unwrap(), 90.0);
        assert_eq!(
            l.int("n", 0).unwrap_err().to_string(),
            "t.pbrt: line 3: column 7: parameter \"integer n\": expected one value, found 2"
        );
        assert_eq!(
            l.triples("P").unwrap().unwrap(),
            vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
        );
        assert_eq!(
            l.spectrum("Kd", true).unwrap(),
            Some(SpectrumParam::Rgb([0.1, 0.2, 0.3]))
        );
        assert!(l.bool("twosided", false).unwrap());
        assert!(
            matches!(l.spectrum("eta", false).unwrap(), Some(SpectrumParam::Named(n, _)) if n == "metal-Au-eta")
        );
        let e = l.string("fov").unwrap_err().to_string();
        assert_eq!(
            e,
            "t.pbrt: line 3: column 7: parameter \"float fov\": expected type string"
        );
        assert_eq!(l.unused().count(), 0);
    }

    #[test]
    fn declarations_and_values_are_checked() {
        let e = Param::new("floaty x", Values::Num(vec![1.0]), loc()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.pbrt: line 3: column 7: unknown parameter type 'floaty' (of \"floaty x\")"
        );
        assert!(Param::new("float", Values::Num(vec![1.0]), loc()).is_err());
        assert!(Param::new("integer n", Values::Num(vec![1.5]), loc()).is_err());
        assert!(Param::new("string s", Values::Num(vec![1.0]), loc()).is_err());
        let odd = list(vec![("point3 P", Values::Num(vec![1.0, 2.0]))]);
        assert!(odd.triples("P").is_err());
        let l = list(vec![
            ("float a", Values::Num(vec![1.0])),
            ("float b", Values::Num(vec![1.0])),
        ]);
        l.float("a", 0.0).unwrap();
        assert_eq!(
            l.unused().map(|p| p.name.as_str()).collect::<Vec<_>>(),
            ["b"]
        );
    }
}
