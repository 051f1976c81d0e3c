//! The order and grouping of one file's findings in text output.
//!
//! [`by_position`] orders findings as they stand in the file: findings without a position
//! (about the whole file, or naming a value that is absent) first, then by byte offset in the
//! JSON text, which is line and column order in a .gltf and byte order in a .glb. Findings at
//! one place keep the order the rules gave them. [`fold`] then groups the findings of each
//! code whose messages are the same (they differ only in where they stand), so that a finding
//! repeated a thousand times in one file is one entry with its count and its first positions
//! instead of a thousand lines; each group stands where its first finding stands. Findings of
//! one code with different messages (two undeclared extensions, a missing buffer and a missing
//! image) call for different fixes and stay apart. Both take findings and return references in a new order: reports are not changed,
//! so other formats and the report's counts see every finding as the rules produced it.

use crate::validate::Finding;

/// `findings` in file order: without a position first, then by byte offset (stable).
pub fn by_position(findings: &[Finding]) -> Vec<&Finding> {
    by_position_of(&findings.iter().collect::<Vec<_>>())
}

/// [`by_position`] for findings already borrowed.
pub fn by_position_of<'a>(findings: &[&'a Finding]) -> Vec<&'a Finding> {
    let mut sorted = findings.to_vec();
    sorted.sort_by_key(|f| f.position.map(|p| p.offset));
    sorted
}

/// The findings of one code and message in one file, in file order.
#[derive(Debug, PartialEq)]
pub struct Group<'a> {
    /// The first finding, shown in full.
    pub first: &'a Finding,
    /// The others, shown by position only.
    pub rest: Vec<&'a Finding>,
}

/// Groups findings (in file order) by code and message, each group at its first finding's
/// place.
pub fn fold<'a>(sorted: &[&'a Finding]) -> Vec<Group<'a>> {
    let mut groups: Vec<Group<'a>> = Vec::new();
    let mut index: std::collections::HashMap<(&str, &str), usize> =
        std::collections::HashMap::new();
    for f in sorted {
        let key = (f.diagnostic.code, f.diagnostic.message.as_str());
        match index.get(&key) {
            Some(&i) => groups[i].rest.push(f),
            None => {
                index.insert(key, groups.len());
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
        said(code, &format!("{code} is found"), offset)
    }

    fn said(code: &'static str, message: &str, offset: Option<usize>) -> Finding {
        Finding {
            diagnostic: Diagnostic {
                code,
                message: message.to_string(),
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

    #[test]
    fn findings_of_one_code_with_different_messages_are_not_folded_together() {
        let sheen = "KHR_materials_sheen is used but not declared in extensionsUsed";
        let specular = "KHR_materials_specular is used but not declared in extensionsUsed";
        let findings = [
            said("UNDECLARED_EXTENSION", sheen, Some(10)),
            said("UNDECLARED_EXTENSION", specular, Some(20)),
            said("UNDECLARED_EXTENSION", sheen, Some(30)),
        ];
        let sorted = by_position(&findings);
        let groups = fold(&sorted);
        let shown: Vec<(&str, Vec<Option<usize>>)> = groups
            .iter()
            .map(|g| {
                let mut offsets = vec![g.first.position.map(|p| p.offset)];
                offsets.extend(g.rest.iter().map(|f| f.position.map(|p| p.offset)));
                (g.first.diagnostic.message.as_str(), offsets)
            })
            .collect();
        assert_eq!(
            shown,
            [
                (sheen, vec![Some(10), Some(30)]),
                (specular, vec![Some(20)])
            ]
        );
    }
}
