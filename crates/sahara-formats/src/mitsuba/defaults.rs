//! Scene parameters: `<default name="spp" value="64"/>`, `-D spp=256` on
//! the command line, and `$spp` in any attribute value.
//!
//! As in Mitsuba, a value given on the command line wins over the file's
//! `<default>`, and the first `<default>` of a name wins over later ones;
//! references are replaced in file order, so a `<default>` applies to
//! what follows it. A `$name` with no value is an error naming it; a `$`
//! not followed by a letter, digit or `_` is kept as it is.

use std::collections::HashMap;

use sahara_readers::FormatError;

use super::xml::Node;

/// The values of the scene's parameters.
#[derive(Clone, Debug, Default)]
pub(crate) struct Defaults {
    values: HashMap<String, String>,
}

/// True for the characters of a parameter name.
fn is_name_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

impl Defaults {
    /// The parameters given on the command line (`-D name=value`).
    pub(crate) fn given(pairs: &[(String, String)]) -> Self {
        Self {
            values: pairs.iter().cloned().collect(),
        }
    }

    /// A `<default name= value=>` element: sets the value unless it is
    /// already set.
    pub(crate) fn declare(&mut self, node: &Node) -> Result<(), FormatError> {
        let name = self.substitute(node, node.need("name")?)?;
        let value = self.substitute(node, node.need("value")?)?;
        if name.is_empty() || !name.chars().all(is_name_char) {
            return Err(node.error(format!(
                "<default> name '{name}': a parameter name is letters, digits and '_'"
            )));
        }
        self.values.entry(name).or_insert(value);
        Ok(())
    }

    /// `text` (an attribute of `node`) with every `$name` replaced.
    pub(crate) fn substitute(&self, node: &Node, text: &str) -> Result<String, FormatError> {
        if !text.contains('$') {
            return Ok(text.to_owned());
        }
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(i) = rest.find('$') {
            out.push_str(&rest[..i]);
            let after = &rest[i + 1..];
            let len = after
                .char_indices()
                .find(|&(_, c)| !is_name_char(c))
                .map_or(after.len(), |(k, _)| k);
            if len == 0 {
                out.push('$');
                rest = after;
                continue;
            }
            let name = &after[..len];
            match self.values.get(name) {
                Some(v) => out.push_str(v),
                None => {
                    return Err(node.error(format!(
                        "parameter '${name}' has no value (give it a <default name=\"{name}\" value=\"...\"/> or -D {name}=...)"
                    )))
                }
            }
            rest = &after[len..];
        }
        out.push_str(rest);
        Ok(out)
    }

    /// `node`'s attributes with their references replaced.
    pub(crate) fn substitute_attrs(&self, node: &mut Node) -> Result<(), FormatError> {
        let attrs = std::mem::take(&mut node.attrs);
        let mut out = Vec::with_capacity(attrs.len());
        for (k, v) in attrs {
            let v = self.substitute(node, &v)?;
            out.push((k, v));
        }
        node.attrs = out;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(attrs: &[(&str, &str)]) -> Node {
        Node::at("default", attrs, 3, 5)
    }

    #[test]
    fn the_command_line_wins_then_the_first_default() {
        let mut d = Defaults::given(&[("spp".into(), "256".into())]);
        d.declare(&node(&[("name", "spp"), ("value", "16")]))
            .unwrap();
        d.declare(&node(&[("name", "res"), ("value", "64")]))
            .unwrap();
        d.declare(&node(&[("name", "res"), ("value", "32")]))
            .unwrap();
        let n = node(&[]);
        assert_eq!(d.substitute(&n, "$spp x $res").unwrap(), "256 x 64");
        assert_eq!(d.substitute(&n, "$res_2").unwrap_err().to_string(), "t.xml: line 3: column 5: parameter '$res_2' has no value (give it a <default name=\"res_2\" value=\"...\"/> or -D res_2=...)");
        assert_eq!(d.substitute(&n, "a $ b $").unwrap(), "a $ b $");
        assert_eq!(d.substitute(&n, "$res.obj").unwrap(), "64.obj");
    }
}
