//! The PATHS tree as openusd 0.6's `build_compressed_paths` walks it, lengths only.
//!
//! Entry i names its path (`path_indices[i]`), the token appended to its parent's path
//! (`tokens[i]`, negative for a property) and where the walk goes next (`jumps[i]`: -1 a
//! child follows, 0 a sibling follows, n > 0 a child follows and a sibling is n entries
//! on, anything else: neither). openusd follows these without checking them: two entries
//! that jump to the same place make it walk that subtree twice, and a chain of them makes
//! the walk exponential; each path string is its parent's plus a token, so a deep chain of
//! long tokens adds up quadratically. Here each entry must be reached once, and the
//! strings' lengths must add up to the budget. Each name must also be one USD allows (an
//! identifier, namespaced for a property, or a variant selection `{set=selection}`), as
//! Pixar's reader requires: openusd parses paths by their punctuation, and a stray `}` in a
//! prim name sent its composition into unbounded recursion.

use super::Refusal;

/// What a token may name in a path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Name {
    /// A prim or a property.
    Identifier,
    /// A property only (`primvars:displayColor`).
    Namespaced,
    /// A variant selection (`{look=plain}`), after a prim.
    Variant,
    /// A variant's name that is not an identifier (`red-1`), in a list of variants.
    Selection,
    Invalid,
}

impl Name {
    pub fn of(token: &[u8]) -> Self {
        let Ok(text) = std::str::from_utf8(token) else {
            return Name::Invalid;
        };
        let identifier = |s: &str| {
            let mut chars = s.chars();
            chars.next().is_some_and(|c| c == '_' || c.is_alphabetic())
                && chars.all(|c| c == '_' || c.is_alphanumeric())
        };
        let selection = |s: &str| s.chars().all(|c| c.is_alphanumeric() || "_|-.".contains(c));
        if identifier(text) {
            Name::Identifier
        } else if text.split(':').all(identifier) {
            Name::Namespaced
        } else if !text.is_empty() && !text.starts_with('.') && selection(text) {
            Name::Selection
        } else {
            match text.strip_prefix('{').and_then(|t| t.strip_suffix('}')) {
                Some(t) => match t.split_once('=') {
                    Some((set, choice)) if identifier(set) && selection(choice) => Name::Variant,
                    _ => Name::Invalid,
                },
                None => Name::Invalid,
            }
        }
    }
}

/// The three decoded arrays of the PATHS section.
pub(super) struct Tree<'a> {
    pub path_indices: &'a [i32],
    pub tokens: &'a [i32],
    pub jumps: &'a [i32],
}

impl Tree<'_> {
    /// The length of every path openusd builds, by path index (0 for an index it never
    /// builds), for `path_count` paths whose tokens have `token_lengths`; refused if an
    /// entry is reached twice or out of range, or if the lengths add up beyond `budget`.
    pub fn lengths(
        &self,
        path_count: usize,
        token_lengths: &[u64],
        names: &[Name],
        budget: u64,
    ) -> Result<Vec<u64>, Refusal> {
        let count = self.jumps.len();
        if count == 0 {
            return Ok(vec![0; path_count]);
        }
        let slot = |i: i32| -> Result<usize, Refusal> {
            usize::try_from(i)
                .ok()
                .filter(|&i| i < path_count)
                .ok_or_else(|| format!("PATHS: an entry names path {i} of {path_count}"))
        };
        let mut lengths = vec![0u64; path_count];
        let mut seen = vec![false; count];
        let mut total = 0u64;
        // (next entry, length of the parent's path; 0: the next entry is the root)
        let mut pending = vec![(0usize, 0u64)];
        while let Some((mut index, mut parent)) = pending.pop() {
            loop {
                if index >= count || std::mem::replace(&mut seen[index], true) {
                    return Err(format!(
                        "PATHS: the tree's jumps reach entry {index} twice or beyond the {count} entries"
                    ));
                }
                let length = if parent == 0 {
                    let root = slot(i32::try_from(index).unwrap_or(-1))?;
                    lengths[root] = 1;
                    // openusd's parent becomes "/" for the rest of this entry.
                    parent = 1;
                    1
                } else {
                    let token = self.tokens[index].unsigned_abs() as usize;
                    let name = token_lengths.get(token).ok_or_else(|| {
                        format!(
                            "PATHS: an entry names token {token} of {}",
                            token_lengths.len()
                        )
                    })?;
                    let property = self.tokens[index] < 0;
                    match (names[token], property) {
                        (Name::Identifier, _)
                        | (Name::Namespaced, true)
                        | (Name::Variant, false) => {}
                        _ => {
                            return Err(format!(
                                "PATHS: token {token} is not a valid {} name",
                                if property { "property" } else { "prim" }
                            ));
                        }
                    }
                    let length = parent + 1 + name;
                    lengths[slot(self.path_indices[index])?] = length;
                    length
                };
                total = total.saturating_add(length);
                if total > budget {
                    return Err(format!(
                        "PATHS: the paths' names add up to more than the {budget} bytes allowed"
                    ));
                }
                let jump = self.jumps[index];
                let child = jump > 0 || jump == -1;
                if child && jump > 0 {
                    pending.push((index + jump as usize, parent));
                }
                if child {
                    parent = lengths[slot(self.path_indices[index])?];
                } else if jump != 0 {
                    break;
                }
                index += 1;
            }
        }
        Ok(lengths)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The root, /A with a child /A/b, and /A's sibling /B; tokens "", "A", "b", "B".
    const TOKENS: [u64; 4] = [0, 1, 1, 1];
    const NAMES: [Name; 4] = [
        Name::Invalid,
        Name::Identifier,
        Name::Identifier,
        Name::Identifier,
    ];

    fn lengths(jumps: &[i32], budget: u64) -> Result<Vec<u64>, Refusal> {
        let n = jumps.len() as i32;
        let indices: Vec<i32> = (0..n).collect();
        let tree = Tree {
            path_indices: &indices,
            tokens: &indices,
            jumps,
        };
        tree.lengths(jumps.len(), &TOKENS, &NAMES, budget)
    }

    #[test]
    fn a_tree_gives_each_path_its_parents_length_plus_its_name() {
        // root: child; A: child and sibling 2 on; b: leaf; B: leaf.
        assert_eq!(lengths(&[-1, 2, -2, -2], 100), Ok(vec![1, 3, 5, 3]));
    }

    #[test]
    fn jumps_that_reach_an_entry_twice_are_refused() {
        // Each entry has a child (the next) and a sibling (also the next): openusd would
        // walk entry i 2^i times.
        let m = lengths(&[-1, 1, 1, -2], 100).unwrap_err();
        assert!(m.contains("reach entry 3 twice"), "{m}");
        let m = lengths(&[-1, 7, -2, -2], 100).unwrap_err();
        assert!(m.contains("beyond the 4 entries"), "{m}");
    }

    #[test]
    fn names_are_identifiers_namespaced_properties_or_variant_selections() {
        for (token, name) in [
            ("hair", Name::Identifier),
            ("_c2_bézier", Name::Identifier),
            ("primvars:displayColor", Name::Namespaced),
            ("{look=plain}", Name::Variant),
            ("{look=}", Name::Variant),
            ("c2_cubic_be}ier", Name::Invalid),
            ("2d", Name::Selection),
            ("a/b", Name::Invalid),
            ("", Name::Invalid),
            ("{look}", Name::Invalid),
            ("[/target]", Name::Invalid),
            ("red-1", Name::Selection),
            (".", Name::Invalid),
            ("..", Name::Invalid),
        ] {
            assert_eq!(Name::of(token.as_bytes()), name, "{token}");
        }
        let indices = [0, 1, 2, 3];
        let names = [
            Name::Invalid,
            Name::Identifier,
            Name::Namespaced,
            Name::Namespaced,
        ];
        let tree = |tokens: &[i32]| {
            Tree {
                path_indices: &indices,
                tokens,
                jumps: &[-1, -1, 0, -2],
            }
            .lengths(4, &TOKENS, &names, 100)
        };
        // A namespaced name names a property (negative token), not a prim.
        assert!(tree(&[0, 1, -2, -3]).is_ok());
        let m = tree(&[0, 1, -2, 3]).unwrap_err();
        assert!(m.contains("token 3 is not a valid prim name"), "{m}");
    }

    #[test]
    fn names_adding_up_beyond_the_budget_are_refused() {
        assert!(lengths(&[-1, 2, -2, -2], 12).is_ok());
        let m = lengths(&[-1, 2, -2, -2], 11).unwrap_err();
        assert!(m.contains("add up to more than the 11 bytes"), "{m}");
    }
}
