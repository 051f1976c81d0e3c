//! The order and grouping of one file's findings in text output.
//!
//! [`by_position`] orders findings as they stand in the file: findings without a position
//! (about the whole file, or naming a value that is absent) first, then by byte offset in the
//! JSON text, which is line and column order in a .gltf and byte order in a .glb. Findings at
//! one place keep the order the rules gave them. [`fold`] then groups the findings of each
//! code, so that a code repeated a thousand times in one file is one entry with its count and
//! its first positions instead of a thousand lines; each group stands where its first finding
//! stands. Both take findings and return references in a new order: reports are not changed,
//! so other formats and the report's counts see every finding as the rules produced it.

use crate::validate::Finding;

/// `findings` in file order: without a position first, then by byte offset (stable).
pub fn by_position(findings: &[Finding]) -> Vec<&Finding> {
    let mut sorted: Vec<&Finding> = findings.iter().collect();
    sorted.sort_by_key(|f| f.position.map(|p| p.offset));
    sorted
}

/// The findings of one code in one file, in file order.
#[derive(Debug, PartialEq)]
pub struct Group<'a> {
    /// The first finding, shown in full.
    pub first: &'a Finding,
    /// The others, shown by position only.
    pub rest: Vec<&'a Finding>,
}

/// Groups findings (in file order) by code, each group at its first finding's place.
pub fn fold<'a>(sorted: &[&'a Finding]) -> Vec<Group<'a>> {
    let mut groups: Vec<Group<'a>> = Vec::new();
    let mut index: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    for f in sorted {
        match index.get(f.diagnostic.code) {
            Some(&i) => groups[i].rest.push(f),
            None => {
                index.insert(f.diagnostic.code, groups.len());
                groups.push(Group {
                    first: f,
                    rest: Vec::new(),
                });
            }
        }
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asset::position::Position;
    use crate::diagnostics::{Diagnostic, Severity};

    fn finding(code: &'static str, offset: Option<usize>) -> Finding {
        Finding {
            diagnostic: Diagnostic {
                code,
                message: format!("{code} at {offset:?}"),
                severity: Severity::Warning,
                pointer: String::new(),
                position: None,
            },
            position: offset.map(|offset| Position {
                line: 1,
                column: offset + 1,
                offset,
            }),
        }
    }

    fn offsets(findings: &[&Finding]) -> Vec<(&'static str, Option<usize>)> {
        findings
            .iter()
            .map(|f| (f.diagnostic.code, f.position.map(|p| p.offset)))
            .collect()
    }

    #[test]
    fn findings_without_a_position_come_first_then_by_offset_keeping_rule_order() {
        let findings = [
            finding("B", Some(30)),
            finding("A", Some(10)),
            finding("C", None),
            finding("D", Some(10)),
            finding("E", None),
        ];
        assert_eq!(
            offsets(&by_position(&findings)),
            [
                ("C", None),
                ("E", None),
                ("A", Some(10)),
                ("D", Some(10)),
                ("B", Some(30))
            ]
        );
    }

    #[test]
    fn each_code_is_one_group_at_its_first_place() {
        let findings = [
            finding("X", Some(50)),
            finding("Y", Some(20)),
            finding("X", Some(10)),
            finding("X", Some(40)),
        ];
        let sorted = by_position(&findings);
        let groups = fold(&sorted);
        assert_eq!(groups.len(), 2);
        assert_eq!(offsets(&[groups[0].first]), [("X", Some(10))]);
        assert_eq!(offsets(&groups[0].rest), [("X", Some(40)), ("X", Some(50))]);
        assert_eq!(offsets(&[groups[1].first]), [("Y", Some(20))]);
        assert!(groups[1].rest.is_empty());
        assert!(fold(&[]).is_empty());
    }
}
