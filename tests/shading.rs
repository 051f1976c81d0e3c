//! The shading API as other modules call it, and, in a build with the `bench` feature,
//! `velvet bench accuracy` as developers run it.

use velvet::migrate::roughness::{self, Direction, RoughnessMapping};
use velvet::shading::layering::{sheen_to_fuzz_attenuation_difference, FuzzParams, SheenParams};
use velvet::shading::mapping::layer_match;
use velvet::shading::{sheen_albedo, AlbedoMethod};

#[cfg(feature = "bench")]
fn velvet(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .output()
        .expect("run velvet")
}

#[test]
fn every_method_answers_through_one_signature() {
    let q = sheen_albedo(0.5, 0.5, AlbedoMethod::Quadrature);
    for m in AlbedoMethod::ALL {
        let v = sheen_albedo(0.5, 0.5, m);
        assert!(
            (v - q).abs() <= m.ordinary_bound(),
            "{}: {v} vs {q}",
            m.name()
        );
    }
}

#[test]
fn sheen_to_fuzz_difference_uses_the_fuzz_model_and_the_mapping_narrows_it() {
    let sheen = SheenParams {
        color_max3: 0.6,
        roughness: 0.4,
    };
    let copied = sheen_to_fuzz_attenuation_difference(
        sheen,
        FuzzParams {
            weight: 0.6,
            roughness: 0.4,
        },
    );
    assert_eq!(copied.curve.len(), 65);
    assert_eq!(copied.fuzz_reflectance, "fuzz R (quadrature)");
    // Same roughness number, different lobes: the attenuations differ.
    assert!(copied.max_difference > 0.02, "{}", copied.max_difference);
    let fitted = layer_match(
        sheen,
        FuzzParams {
            weight: 0.6,
            roughness: roughness::map(0.4, Direction::SheenToFuzz, RoughnessMapping::Fitted),
        },
    );
    let identity = layer_match(
        sheen,
        FuzzParams {
            weight: 0.6,
            roughness: 0.4,
        },
    );
    assert!(
        fitted.rms < 0.5 * identity.rms,
        "{fitted:?} vs {identity:?}"
    );
    assert!(fitted.max_ordinary < identity.max_ordinary);
}

#[cfg(feature = "bench")]
#[test]
fn points_file_gives_csv_with_one_row_per_point() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("points.csv");
    std::fs::write(&file, "mu,r\n0,0\n0.5,0.5\n1,1\n").unwrap();
    let out = velvet(&["bench", "accuracy", "--points", file.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "mu,r,quadrature,lut16,lut32,fit");
    assert_eq!(lines.len(), 4);
    // r = 0 exactly: the quadrature gives the α → 0 limit, 0.
    assert!(lines[1].starts_with("0,0,0,"), "{}", lines[1]);
    for line in &lines[1..] {
        let values: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        assert_eq!(values.len(), 6);
        assert!(values.iter().all(|v| v.is_finite()));
    }
}

#[cfg(feature = "bench")]
#[test]
fn a_bad_points_row_exits_2_naming_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("bad.csv");
    std::fs::write(&file, "mu,r\n0.5,0.5\n0.5;0.5\n").unwrap();
    let out = velvet(&["bench", "accuracy", "--points", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(
        err,
        format!(
            "velvet: {}: line 3: expected 2 fields (mu,r), found 1\n",
            file.display()
        )
    );
}

#[cfg(feature = "bench")]
#[test]
fn a_missing_points_file_exits_2_naming_it() {
    let out = velvet(&["bench", "accuracy", "--points", "no-such-points.csv"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.starts_with("velvet: no-such-points.csv: cannot read: "),
        "{err}"
    );
}

#[cfg(feature = "bench")]
#[test]
fn points_and_plot_together_are_a_usage_error() {
    let out = velvet(&["bench", "accuracy", "--points", "a.csv", "--plot", "b.svg"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be used with"));
}

/// The default roughness budget, measured by appearance: moving the fuzz roughness by the
/// budget from the mapping's α(r) adds little to the cosine-weighted rms difference in
/// reflectance that the mapping itself leaves, while three times the budget would add more
/// than the smallest difference the mapping leaves anywhere (docs/shading.md, "The roughness
/// budget").
#[test]
fn the_default_roughness_budget_adds_little_to_the_mappings_own_appearance_difference() {
    use velvet::migrate::budget::DEFAULT_BUDGET;
    use velvet::shading::mapping::{fuzz_roughness_for_sheen, mapping_rms};
    let mut least_own = f64::INFINITY;
    let mut most_added_at_budget: f64 = 0.0;
    let mut most_added_at_triple: f64 = 0.0;
    for i in 1..=20 {
        let r = f64::from(i) / 20.0;
        let alpha = fuzz_roughness_for_sheen(r);
        let own = mapping_rms(r, alpha);
        let added = |d: f64| {
            mapping_rms(r, (alpha + d).min(1.0)).max(mapping_rms(r, (alpha - d).max(0.0))) - own
        };
        least_own = least_own.min(own);
        most_added_at_budget = most_added_at_budget.max(added(DEFAULT_BUDGET));
        most_added_at_triple = most_added_at_triple.max(added(3.0 * DEFAULT_BUDGET));
    }
    assert!((0.0085..0.0095).contains(&least_own), "{least_own}");
    assert!(most_added_at_budget < 0.0025, "{most_added_at_budget}");
    assert!(most_added_at_budget < least_own / 3.0);
    assert!(most_added_at_triple > least_own, "{most_added_at_triple}");
}
