//! The protocol's four ray sets by name.

use std::fmt;

use crate::runner::Query;

/// One of the protocol's ray sets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SetKind {
    /// One ray per pixel centre from the camera.
    Primary,
    /// Occlusion rays from the primary hits to the point light.
    Shadow,
    /// Cosine-weighted rays from the primary hits.
    Diffuse,
    /// Random rays in the bounding box.
    Random,
}

impl SetKind {
    /// All four, in the protocol's order.
    pub const ALL: [SetKind; 4] = [
        SetKind::Primary,
        SetKind::Shadow,
        SetKind::Diffuse,
        SetKind::Random,
    ];

    /// The protocol's name (`primary`, `shadow`, `diffuse`, `random`).
    pub fn name(&self) -> &'static str {
        match self {
            SetKind::Primary => "primary",
            SetKind::Shadow => "shadow",
            SetKind::Diffuse => "diffuse",
            SetKind::Random => "random",
        }
    }

    /// The set called `name`, if any.
    pub fn parse(name: &str) -> Option<SetKind> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The query the set is traced with: any hit for `shadow`, closest hit
    /// for the others.
    pub fn query(&self) -> Query {
        match self {
            SetKind::Shadow => Query::AnyHit,
            _ => Query::ClosestHit,
        }
    }

    /// True for the sets generated from the primary hits.
    pub fn is_secondary(&self) -> bool {
        matches!(self, SetKind::Shadow | SetKind::Diffuse)
    }
}

impl fmt::Display for SetKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for s in SetKind::ALL {
            assert_eq!(SetKind::parse(s.name()), Some(s));
        }
        assert_eq!(SetKind::parse("Primary"), None);
        assert_eq!(SetKind::Shadow.query(), Query::AnyHit);
        assert_eq!(SetKind::Random.query(), Query::ClosestHit);
    }
}
