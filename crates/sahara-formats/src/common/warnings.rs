//! Loading warnings, one line per kind with a count: a scene with ten
//! thousand curves says so once, not ten thousand times.

use std::collections::HashMap;

use super::position::Loc;

/// Warnings gathered while loading, by kind, in the order first seen.
#[derive(Debug, Default)]
pub(crate) struct Warnings {
    kinds: Vec<(String, usize, String)>,
    index: HashMap<String, usize>,
}

impl Warnings {
    /// Counts one occurrence of `kind` at `at` (the first one's place is shown).
    pub(crate) fn add(&mut self, kind: impl Into<String>, at: &Loc) {
        self.add_at(kind, at.short());
    }

    /// Counts one occurrence of `kind`, placed by `at` (a file name or `file:line:column`).
    pub(crate) fn add_at(&mut self, kind: impl Into<String>, at: String) {
        let kind = kind.into();
        match self.index.get(&kind) {
            Some(&i) => self.kinds[i].1 += 1,
            None => {
                self.index.insert(kind.clone(), self.kinds.len());
                self.kinds.push((kind, 1, at));
            }
        }
    }

    /// How many times `kind` was counted.
    #[cfg(test)]
    pub(crate) fn count(&self, kind: &str) -> usize {
        self.index.get(kind).map_or(0, |&i| self.kinds[i].1)
    }

    /// One line per kind: `place: kind` and, if it happened more than once,
    /// how often.
    pub(crate) fn into_lines(self) -> Vec<String> {
        self.kinds
            .into_iter()
            .map(|(kind, n, at)| {
                if n == 1 {
                    format!("{at}: {kind}")
                } else {
                    format!("{at}: {kind} ({n} times; the first here)")
                }
            })
            .collect()
    }
}
