//! The roughness choice between the sheen and fuzz lobes, in one place.
//!
//! Sheen ("Charlie" distribution, α = r²) and fuzz (an SGGX fibre volume) read roughness on
//! different scales, and no fitted mapping between them exists yet: both directions copy the
//! value. A mapping that preserves appearance replaces [`map`] and nothing else. While the
//! mapping is a pure scale (the identity is), a roughness texture can be carried unchanged
//! (both layers read alpha, linear): a non-linear mapping would need that texture baked.

/// Which way a roughness value is carried.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// sheenRoughnessFactor → fuzzRoughnessFactor.
    SheenToFuzz,
    /// fuzzRoughnessFactor → sheenRoughnessFactor (the fallback sheen).
    FuzzToSheen,
}

/// The roughness of the other layer that stands for `roughness` of this one. For now the
/// identity in both directions.
pub fn map(roughness: f64, direction: Direction) -> f64 {
    match direction {
        Direction::SheenToFuzz | Direction::FuzzToSheen => roughness,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mapping_is_the_identity_at_the_ends_and_between() {
        for r in [0.0, 0.3, 0.5, 1.0] {
            assert_eq!(map(r, Direction::SheenToFuzz), r);
            assert_eq!(map(r, Direction::FuzzToSheen), r);
        }
    }
}
