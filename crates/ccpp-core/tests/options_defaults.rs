//! A partial options section keeps the planner's own defaults for what it omits, at every
//! depth: removing any one field from the serialized defaults reads back the defaults (or is
//! refused), never another value. `ba_star_extended.extension` and `bsa_extended.extension`
//! once took the shared extension component's `reach_r` 4 instead of their planner's 0.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use ccpp_core::planners::PlannerOptions;
use serde_json::{Map, Value};

/// Every path (list of keys) to an object member of `v`.
fn paths(v: &Value, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    if let Value::Object(m) = v {
        for (k, child) in m {
            prefix.push(k.clone());
            out.push(prefix.clone());
            paths(child, prefix, out);
            prefix.pop();
        }
    }
}

fn member<'a>(v: &'a mut Value, path: &[String]) -> &'a mut Map<String, Value> {
    let mut cur = v;
    for k in path {
        cur = cur.get_mut(k).unwrap();
    }
    cur.as_object_mut().unwrap()
}

#[test]
fn every_omitted_field_reads_back_as_the_planners_default() {
    let defaults = PlannerOptions::default();
    let full = serde_json::to_value(&defaults).unwrap();
    let mut all = Vec::new();
    paths(&full, &mut Vec::new(), &mut all);
    let mut accepted = Vec::new();
    for path in &all {
        let (last, parent) = path.split_last().unwrap();
        // Without the field...
        let mut v = full.clone();
        member(&mut v, parent).remove(last);
        // ...and, for a nested section, as an empty section.
        let mut empty = full.clone();
        let emptied = full
            .pointer(&format!("/{}", path.join("/")))
            .unwrap()
            .is_object();
        if emptied {
            member(&mut empty, parent).insert(last.clone(), Value::Object(Map::new()));
        }
        for (what, v) in [("omitted", Some(v)), ("empty", emptied.then_some(empty))] {
            let Some(v) = v else { continue };
            // Refusing (an enum with no variant named) is fine; another value is not.
            if let Ok(back) = serde_json::from_value::<PlannerOptions>(v) {
                assert_eq!(
                    back,
                    defaults,
                    "{what} {} reads back as another value",
                    path.join(".")
                );
                accepted.push(path.join("."));
            }
        }
    }
    for must in [
        "ba_star_extended.extension.reach_r",
        "ba_star_extended.extension.merge_segments",
        "bsa_extended.extension.reach_r",
        "bsa_extended.extension",
        "ba_star_extended.ba_star.smoothing",
        "bsa_bfs.exec.pid.dt_s",
        "rect_boustrophedon.exec.pid.linear.kp",
    ] {
        assert!(accepted.iter().any(|p| p == must), "{must} was refused");
    }
}

#[test]
fn a_partial_extension_section_changes_only_its_fields() {
    let o: PlannerOptions = serde_json::from_str(
        r#"{"bsa_extended": {"extension": {"merge_segments": false}},
            "ba_star_extended": {"extension": {"lane_ends": true}}}"#,
    )
    .unwrap();
    let d = PlannerOptions::default();
    assert_eq!(o.bsa_extended.extension.reach_r, 0.0);
    assert!(!o.bsa_extended.extension.merge_segments);
    assert_eq!(
        o.ba_star_extended.extension.reach_r,
        d.ba_star_extended.extension.reach_r
    );
    assert!(o.ba_star_extended.extension.lane_ends);
    // ba-star-extended's own clean-up defaults, not the component's.
    assert_eq!(o.ba_star_extended.extension.leave_group, 12);
    assert_ne!(
        o.ba_star_extended.extension.leave_group,
        ccpp_core::planners::extension::ExtensionOptions::default().leave_group
    );
    // A PID controller section keeps that controller's defaults (not `PidGains::default`).
    let o: PlannerOptions =
        serde_json::from_str(r#"{"bsa_bfs": {"exec": {"pid": {"angular": {"kp": 5.0}}}}}"#)
            .unwrap();
    let ccpp_core::exec::Execution::Pid(p) = o.bsa_bfs.exec else {
        panic!("not pid")
    };
    assert_eq!(p.angular.kp, 5.0);
    assert_eq!(
        p.angular.output_limit,
        ccpp_core::exec::PidOptions::default().angular.output_limit
    );
    // A field given as null or unknown is refused, as for the full type.
    for bad in [
        r#"{"bsa_extended": {"extension": {"reach_r": null}}}"#,
        r#"{"bsa_extended": {"extension": {"reach": 1}}}"#,
    ] {
        assert!(
            serde_json::from_str::<PlannerOptions>(bad).is_err(),
            "{bad}"
        );
    }
}

/// The config fuzzer's seed `fuzz/corpus/config/defaults.json` is the serialized defaults: a
/// seed with fields that no longer exist is refused as a whole and seeds nothing. Run with
/// `CCPP_BLESS=1` to rewrite it after an options change (`cargo test -p ccpp-core --test
/// integration the_fuzz_corpus`).
#[test]
fn the_fuzz_corpus_defaults_are_the_current_defaults() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz/corpus/config/defaults.json");
    let want = serde_json::to_value(PlannerOptions::default()).unwrap();
    if std::env::var_os("CCPP_BLESS").is_some() {
        let text = serde_json::to_string_pretty(&want).unwrap();
        std::fs::write(&path, text + "\n").unwrap();
    }
    let text = std::fs::read_to_string(&path).unwrap();
    let got: Value = serde_json::from_str(&text).unwrap();
    assert!(
        got == want,
        "{} is stale; rewrite it with CCPP_BLESS=1 cargo test -p ccpp-core --test integration the_fuzz_corpus",
        path.display()
    );
    // And it reads back as the defaults.
    let back: PlannerOptions = serde_json::from_str(&text).unwrap();
    assert_eq!(serde_json::to_value(back).unwrap(), want);
}

/// `planners::build` refuses an option out of its range, naming its section and field, where
/// it ran the planner with the default instead (`tile_side_m: -1` built BA* with its tiles
/// of the robot's diameter, without a word); valid options still build.
#[test]
fn build_by_name_refuses_an_option_out_of_its_range() {
    use ccpp_core::grid::GridMap;
    use ccpp_core::planners::{build, BuildError};
    use ccpp_core::world::{Robot, World};
    let map: GridMap = "##########\n#........#\n#........#\n#........#\n##########"
        .parse()
        .unwrap();
    let world = World::new(map, Robot::new(0.5), None).unwrap();
    let mut opts = PlannerOptions::default();
    opts.ba_star.tile_side_m = Some(-1.0);
    match build("ba-star", &opts, &world) {
        Err(BuildError::Options(e)) => {
            assert!(e.to_string().contains("ba_star.tile_side_m"), "{e}");
        }
        other => panic!("{:?}", other.map(|p| p.name())),
    }
    opts.ba_star.tile_side_m = Some(1.0);
    assert_eq!(build("ba-star", &opts, &world).unwrap().name(), "ba-star");
    assert!(matches!(
        build("ba-star-x", &opts, &world),
        Err(BuildError::Unknown(_))
    ));
}
