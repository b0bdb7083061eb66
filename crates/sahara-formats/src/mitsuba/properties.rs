//! A plugin element (`<bsdf type="diffuse">`, `<shape type="obj">` ...)
//! as an [`Object`]: its typed properties and its nested objects and
//! references, each remembered as used or not, so that what nothing
//! asked for is reported.
//!
//! Properties: `integer`, `float`, `boolean`, `string`, `rgb`, `srgb`,
//! `spectrum`, `blackbody`, `point`, `vector`, `transform`. An integer
//! may stand where a float is asked for (not the reverse); a float where
//! a colour is asked for is that grey. A property given twice is an
//! error, as in Mitsuba.

use std::cell::Cell;
use std::path::PathBuf;

use glam::{DMat4, DVec3};
use sahara_readers::FormatError;

use super::expand::Search;
use super::spectra::{numbers, parse_rgb, parse_spectrum, parse_temperature, Color};
use super::transform::parse_transform;
use super::xml::Node;
use crate::common::position::Loc;
use crate::common::warnings::Warnings;

/// Tags of nested objects.
pub(crate) const OBJECT_TAGS: &[&str] = &[
    "bsdf",
    "texture",
    "shape",
    "emitter",
    "sensor",
    "film",
    "sampler",
    "rfilter",
    "integrator",
    "medium",
    "phase",
    "volume",
];

/// A property's value.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Value {
    /// `<integer>`.
    Int(i64),
    /// `<float>`.
    Float(f64),
    /// `<boolean>`.
    Bool(bool),
    /// `<string>`.
    Str(String),
    /// `<rgb>`, `<srgb>`, `<spectrum>`, `<blackbody>`.
    Color(Color),
    /// `<point>`, `<vector>`.
    Vector(DVec3),
    /// `<transform>`.
    Transform(DMat4),
}

impl Value {
    /// What the file calls this kind of value.
    fn kind(&self) -> &'static str {
        match self {
            Value::Int(_) => "an <integer>",
            Value::Float(_) => "a <float>",
            Value::Bool(_) => "a <boolean>",
            Value::Str(_) => "a <string>",
            Value::Color(_) => "a colour",
            Value::Vector(_) => "a <point> or <vector>",
            Value::Transform(_) => "a <transform>",
        }
    }
}

/// A named property.
#[derive(Debug)]
pub(crate) struct Prop {
    /// Its name.
    pub(crate) name: String,
    /// Its value.
    pub(crate) value: Value,
    /// Where it is written.
    pub(crate) loc: Loc,
    used: Cell<bool>,
}

impl Prop {
    /// An error at this property.
    pub(crate) fn error(&self, message: impl std::fmt::Display) -> FormatError {
        self.loc.error(format!("'{}': {message}", self.name))
    }

    fn wrong(&self, expected: &str) -> FormatError {
        self.error(format!("expected {expected}, found {}", self.value.kind()))
    }
}

/// A nested object: written in place, or a `<ref id=...>`.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Child<'a> {
    /// An element written inside.
    Node(&'a Node),
    /// A reference to an object with an `id`.
    Ref(&'a Node),
}

impl<'a> Child<'a> {
    /// The element: the object itself or the `<ref>`.
    pub(crate) fn node(&self) -> &'a Node {
        match self {
            Child::Node(n) | Child::Ref(n) => n,
        }
    }
}

/// A nested object with its `name` attribute, if any.
#[derive(Debug)]
pub(crate) struct Entry<'a> {
    /// The `name` attribute (a texture's parameter name).
    pub(crate) name: Option<&'a str>,
    /// The object or reference.
    pub(crate) child: Child<'a>,
    used: Cell<bool>,
}

impl Entry<'_> {
    /// Marks it used.
    pub(crate) fn take(&self) {
        self.used.set(true);
    }
}

/// A plugin element: its type, properties and nested objects.
#[derive(Debug)]
pub(crate) struct Object<'a> {
    /// The element.
    pub(crate) node: &'a Node,
    /// The plugin type (`type` attribute).
    pub(crate) ty: &'a str,
    props: Vec<Prop>,
    entries: Vec<Entry<'a>>,
}

/// Reads a property element.
fn property(node: &Node, search: &Search) -> Result<Value, FormatError> {
    let value = || node.need("value");
    let one = |what: &str| -> Result<f64, FormatError> {
        let text = value()?;
        match numbers(node, text)?[..] {
            [v] => Ok(v),
            _ => Err(node.error(format!("<{what}> takes one number, found '{text}'"))),
        }
    };
    Ok(match node.tag.as_str() {
        "integer" => {
            let text = value()?.trim();
            Value::Int(text.parse::<i64>().map_err(|_| {
                node.error(format!("<integer> takes a whole number, found '{text}'"))
            })?)
        }
        "float" => Value::Float(one("float")?),
        "boolean" => match value()?.trim().to_ascii_lowercase().as_str() {
            "true" | "1" => Value::Bool(true),
            "false" | "0" => Value::Bool(false),
            other => {
                return Err(node.error(format!("<boolean> takes true or false, found '{other}'")))
            }
        },
        "string" => Value::Str(value()?.to_owned()),
        "rgb" => Value::Color(parse_rgb(node, false)?),
        "srgb" => Value::Color(parse_rgb(node, true)?),
        "spectrum" => {
            let path = node
                .attr("filename")
                .map(|f| search.resolve(&node.folder, f));
            Value::Color(parse_spectrum(node, path.as_deref())?)
        }
        "blackbody" => Value::Color(parse_temperature(node, node.need("temperature")?)?),
        "point" | "vector" => {
            if let Some(v) = node.attr("value") {
                match numbers(node, v)?[..] {
                    [x, y, z] => Value::Vector(DVec3::new(x, y, z)),
                    [s] => Value::Vector(DVec3::splat(s)),
                    ref v => {
                        return Err(node.error(format!(
                            "<{}> takes 3 numbers, found {}",
                            node.tag,
                            v.len()
                        )))
                    }
                }
            } else {
                let c = |k: &str| -> Result<f64, FormatError> {
                    match node.attr(k) {
                        None => Ok(0.0),
                        Some(t) => match numbers(node, t)?[..] {
                            [v] => Ok(v),
                            _ => {
                                Err(node.error(format!("<{}> {k}: expected one number", node.tag)))
                            }
                        },
                    }
                };
                Value::Vector(DVec3::new(c("x")?, c("y")?, c("z")?))
            }
        }
        "transform" => Value::Transform(parse_transform(node)?),
        other => return Err(node.error(format!("unknown property <{other}>"))),
    })
}

impl<'a> Object<'a> {
    /// The object of a plugin element (`search`: where files named by
    /// properties are looked for).
    pub(crate) fn parse(node: &'a Node, search: &Search) -> Result<Object<'a>, FormatError> {
        let ty = node.need("type")?;
        let mut props: Vec<Prop> = Vec::new();
        let mut entries = Vec::new();
        for c in &node.children {
            let tag = c.tag.as_str();
            if tag == "ref" {
                c.need("id")?;
                entries.push(Entry {
                    name: c.attr("name"),
                    child: Child::Ref(c),
                    used: Cell::new(false),
                });
            } else if OBJECT_TAGS.contains(&tag) || (tag == "spectrum" && c.attr("type").is_some())
            {
                entries.push(Entry {
                    name: c.attr("name"),
                    child: Child::Node(c),
                    used: Cell::new(false),
                });
            } else {
                let name = c.need("name")?;
                if props.iter().any(|p| p.name == name) {
                    return Err(c.error(format!("parameter '{name}' is given twice")));
                }
                props.push(Prop {
                    name: name.to_owned(),
                    value: property(c, search)?,
                    loc: c.loc.clone(),
                    used: Cell::new(false),
                });
            }
        }
        Ok(Object {
            node,
            ty,
            props,
            entries,
        })
    }

    /// An error at the element.
    pub(crate) fn error(&self, message: impl std::fmt::Display) -> FormatError {
        self.node.error(message)
    }

    /// What messages call the object: `bsdf 'diffuse'`.
    pub(crate) fn what(&self) -> String {
        format!("{} '{}'", self.node.tag, self.ty)
    }

    /// The property `name`, marked used.
    pub(crate) fn get(&self, name: &str) -> Option<&Prop> {
        let p = self.props.iter().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// True if the property or nested object `name` is given (not marked used).
    pub(crate) fn has(&self, name: &str) -> bool {
        self.props.iter().any(|p| p.name == name)
            || self.entries.iter().any(|e| e.name == Some(name))
    }

    /// A float (an integer is accepted).
    pub(crate) fn float(&self, name: &str, default: f64) -> Result<f64, FormatError> {
        Ok(self.float_opt(name)?.unwrap_or(default))
    }

    /// A float, if given.
    pub(crate) fn float_opt(&self, name: &str) -> Result<Option<f64>, FormatError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Float(v) => Ok(Some(v)),
                Value::Int(v) => Ok(Some(v as f64)),
                _ => Err(p.wrong("a <float>")),
            },
        }
    }

    /// An integer.
    pub(crate) fn int(&self, name: &str, default: i64) -> Result<i64, FormatError> {
        match self.get(name) {
            None => Ok(default),
            Some(p) => match p.value {
                Value::Int(v) => Ok(v),
                _ => Err(p.wrong("an <integer>")),
            },
        }
    }

    /// A boolean.
    pub(crate) fn bool(&self, name: &str, default: bool) -> Result<bool, FormatError> {
        match self.get(name) {
            None => Ok(default),
            Some(p) => match p.value {
                Value::Bool(v) => Ok(v),
                _ => Err(p.wrong("a <boolean>")),
            },
        }
    }

    /// A string, if given.
    pub(crate) fn string(&self, name: &str) -> Result<Option<&str>, FormatError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Str(v) => Ok(Some(v.as_str())),
                _ => Err(p.wrong("a <string>")),
            },
        }
    }

    /// A file named by string property `name`, resolved as Mitsuba does.
    pub(crate) fn file(&self, name: &str, search: &Search) -> Result<Option<PathBuf>, FormatError> {
        Ok(self
            .string(name)?
            .map(|f| search.resolve(&self.node.folder, f)))
    }

    /// A point or vector, if given.
    pub(crate) fn vector(&self, name: &str) -> Result<Option<DVec3>, FormatError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match p.value {
                Value::Vector(v) => Ok(Some(v)),
                _ => Err(p.wrong("a <point> or <vector>")),
            },
        }
    }

    /// A transform (identity if not given).
    pub(crate) fn transform(&self, name: &str) -> Result<DMat4, FormatError> {
        match self.get(name) {
            None => Ok(DMat4::IDENTITY),
            Some(p) => match p.value {
                Value::Transform(m) => Ok(m),
                _ => Err(p.wrong("a <transform>")),
            },
        }
    }

    /// A colour property, if given as a value (a float is a grey).
    pub(crate) fn color(&self, name: &str) -> Result<Option<Color>, FormatError> {
        match self.get(name) {
            None => Ok(None),
            Some(p) => match &p.value {
                Value::Color(c) => Ok(Some(c.clone())),
                Value::Float(v) => Ok(Some(Color::Uniform(*v))),
                Value::Int(v) => Ok(Some(Color::Uniform(*v as f64))),
                _ => Err(p.wrong("a colour (<rgb>, <spectrum>) or a <float>")),
            },
        }
    }

    /// The nested object or reference named `name` (a texture given for a
    /// parameter), marked used.
    pub(crate) fn named(&self, name: &str) -> Option<&Entry<'a>> {
        let e = self.entries.iter().find(|e| e.name == Some(name))?;
        e.take();
        Some(e)
    }

    /// Every nested object and reference, named or not (iterating marks
    /// none used).
    pub(crate) fn entries(&self) -> impl Iterator<Item = &Entry<'a>> {
        self.entries.iter()
    }

    /// The nested objects of tag `tag` written in place (not references),
    /// marked used.
    pub(crate) fn nested(&self, tag: &str) -> Vec<&'a Node> {
        self.entries
            .iter()
            .filter_map(|e| match e.child {
                Child::Node(n) if n.tag == tag => {
                    e.take();
                    Some(n)
                }
                _ => None,
            })
            .collect()
    }

    /// Marks everything used (an object skipped whole).
    pub(crate) fn mark_all_used(&self) {
        self.props.iter().for_each(|p| p.used.set(true));
        self.entries.iter().for_each(|e| e.take());
    }

    /// Warns of every property and nested object nothing asked for.
    pub(crate) fn warn_unused(&self, w: &mut Warnings) {
        for p in self.props.iter().filter(|p| !p.used.get()) {
            w.add(
                format!("{}: unknown parameter '{}', ignored", self.what(), p.name),
                &p.loc,
            );
        }
        for e in self.entries.iter().filter(|e| !e.used.get()) {
            let n = e.child.node();
            w.add(
                format!("{}: nested <{}> not used here, ignored", self.what(), n.tag),
                &n.loc,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mitsuba::xml::parse_text;
    use std::path::Path;

    fn node(text: &str) -> Node {
        parse_text(
            text.as_bytes(),
            "t.xml",
            Path::new("/f"),
            &mut Warnings::default(),
        )
        .unwrap()
    }

    #[test]
    fn every_property_type_reads_and_is_checked() {
        let n = node(
            "<bsdf type=\"x\">\n<integer name=\"i\" value=\"3\"/><float name=\"f\" value=\"0.5\"/>\
             <boolean name=\"b\" value=\"true\"/><string name=\"s\" value=\"hi\"/>\
             <rgb name=\"c\" value=\"1 0.5 0\"/><spectrum name=\"g\" value=\"0.2\"/>\
             <point name=\"p\" x=\"1\" z=\"3\"/><vector name=\"v\" value=\"1, 2, 3\"/>\
             <transform name=\"t\"><translate x=\"1\"/></transform>\
             <texture name=\"tex\" type=\"bitmap\"/><ref id=\"other\"/>\n</bsdf>",
        );
        let o = Object::parse(&n, &Search::new(Path::new("/f"))).unwrap();
        assert_eq!(o.ty, "x");
        assert_eq!(o.int("i", 0).unwrap(), 3);
        assert_eq!(o.float("i", 0.0).unwrap(), 3.0);
        assert_eq!(o.float("f", 0.0).unwrap(), 0.5);
        assert!(o.bool("b", false).unwrap());
        assert_eq!(o.string("s").unwrap(), Some("hi"));
        assert_eq!(
            o.color("c").unwrap(),
            Some(Color::Rgb(DVec3::new(1.0, 0.5, 0.0)))
        );
        assert_eq!(o.color("f").unwrap(), Some(Color::Uniform(0.5)));
        assert_eq!(o.color("g").unwrap(), Some(Color::Uniform(0.2)));
        assert_eq!(o.vector("p").unwrap(), Some(DVec3::new(1.0, 0.0, 3.0)));
        assert_eq!(o.vector("v").unwrap(), Some(DVec3::new(1.0, 2.0, 3.0)));
        assert_eq!(
            o.transform("t").unwrap().transform_point3(DVec3::ZERO),
            DVec3::X
        );
        assert!(o.named("tex").is_some());
        let e = o.int("f", 0).unwrap_err().to_string();
        assert_eq!(
            e,
            "t.xml: line 2: column 30: 'f': expected an <integer>, found a <float>"
        );
        let mut w = Warnings::default();
        o.warn_unused(&mut w);
        let lines = w.into_lines();
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(
            lines[0].starts_with("t.xml:2:")
                && lines[0].ends_with(": bsdf 'x': nested <ref> not used here, ignored"),
            "{lines:?}"
        );
    }

    #[test]
    fn bad_values_and_repeats_are_errors_at_their_element() {
        let e = |t: &str| {
            Object::parse(&node(t), &Search::new(Path::new("/f")))
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            e("<bsdf type=\"x\">\n  <float name=\"a\" value=\"x\"/></bsdf>"),
            "t.xml: line 2: column 3: expected a number, found 'x'"
        );
        assert_eq!(
            e("<bsdf type=\"x\"><integer name=\"a\" value=\"1.5\"/></bsdf>"),
            "t.xml: line 1: column 16: <integer> takes a whole number, found '1.5'"
        );
        assert_eq!(
            e("<bsdf type=\"x\"><float name=\"a\" value=\"1\"/><float name=\"a\" value=\"2\"/></bsdf>"),
            "t.xml: line 1: column 43: parameter 'a' is given twice"
        );
        assert_eq!(
            e("<bsdf><float name=\"a\" value=\"1\"/></bsdf>"),
            "t.xml: line 1: column 1: <bsdf> needs a 'type' attribute"
        );
        assert_eq!(
            e("<bsdf type=\"x\"><color name=\"a\" value=\"1\"/></bsdf>"),
            "t.xml: line 1: column 16: unknown property <color>"
        );
    }
}
