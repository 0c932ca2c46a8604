//! The demo's `replay.html` in headless Chromium at 1280x720, 1366x768, 1920x1080 and 390x844:
//! the page measures the bounding boxes of its side panel's values and posts them out; at the
//! desktop sizes every value must be inside the viewport without scrolling, on the phone the map
//! must fill the width with the panel under it. Screenshots of each size are kept under the test
//! target folder. Skipped without Chromium (CI installs it, see `.ci/run`).

use std::path::Path;
use std::process::Command;

fn chrome(chrome: &Path, profile: &Path) -> Command {
    let mut c = crate::common::headless(chrome, profile);
    c.args(["--hide-scrollbars", "--virtual-time-budget=10000"]);
    c
}

fn self_json(dom: &str) -> Option<serde_json::Value> {
    let a = dom.find("SELFJSON ")? + 9;
    let b = dom[a..].find(" ENDSELFJSON")? + a;
    let text = dom[a..b].replace("&quot;", "\"").replace("&amp;", "&");
    serde_json::from_str(&text).ok()
}

#[test]
fn demo_replay_side_panel_is_visible_at_desktop_sizes_and_usable_on_a_phone() {
    let dir = tempfile::tempdir().unwrap();
    assert_cmd::Command::cargo_bin("ccpp")
        .unwrap()
        .current_dir(dir.path())
        .arg("demo")
        .assert()
        .success();
    let run = dir.path().join("ccpp-demo");
    assert!(run.join("replay.html").is_file());
    let Some(chrome_bin) = crate::common::require_chromium() else {
        return;
    };
    let profile = tempfile::tempdir().unwrap();
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR"));
    for (w, h) in [(1280u32, 720u32), (1366, 768), (1920, 1080), (390, 844)] {
        // An iframe of exactly w x h is a real viewport of that size (a headless window has a
        // minimum width and its own chrome); the page posts its self-test to the wrapper.
        let wrapper = run.join(format!("frame-{w}x{h}.html"));
        std::fs::write(
            &wrapper,
            format!(
                r#"<!DOCTYPE html><html><body style="margin:0"><iframe src="replay.html#selftest" width="{w}" height="{h}" style="border:0;display:block"></iframe><pre id="out">waiting</pre><script>window.addEventListener("message", e => {{ document.getElementById("out").textContent = String(e.data); }});</script></body></html>"#
            ),
        )
        .unwrap();
        let url = format!("file://{}", wrapper.display());
        let mut v = None;
        for _ in 0..3 {
            let o = crate::common::output_within_limit(
                chrome(&chrome_bin, profile.path())
                    .arg("--window-size=2000,1200")
                    .arg("--dump-dom")
                    .arg(&url),
            );
            for l in String::from_utf8_lossy(&o.stderr).lines() {
                let l = l.to_ascii_lowercase();
                assert!(
                    !(l.contains("console") && (l.contains("error") || l.contains("uncaught"))),
                    "{w}x{h}: console error: {l}"
                );
            }
            v = self_json(&String::from_utf8_lossy(&o.stdout));
            if v.is_some() {
                break;
            }
        }
        let v = v.unwrap_or_else(|| panic!("{w}x{h}: no self-test result"));
        assert_eq!(v["pass"], true, "{w}x{h}: {v}");
        // The last frame says the run ended (it said its last region: hostile pass, stop 70).
        assert_eq!(
            (v["state_start"].as_str(), v["state_end"].as_str()),
            (Some("starting"), Some("finished")),
            "{w}x{h}"
        );
        assert_eq!(
            (v["vw"].as_f64(), v["vh"].as_f64()),
            (Some(f64::from(w)), Some(f64::from(h)))
        );
        let boxes: Vec<(String, Vec<f64>)> = v["boxes"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(k, b)| {
                let r = b.as_array().unwrap().iter().map(|x| x.as_f64().unwrap());
                (k.clone(), r.collect())
            })
            .collect();
        let get = |k: &str| boxes.iter().find(|b| b.0 == k).unwrap().1.clone();
        let values: Vec<&(String, Vec<f64>)> = boxes
            .iter()
            .filter(|b| b.0.starts_with("now-") || b.0.starts_with("m-"))
            .collect();
        assert!(values.len() >= 14, "{w}x{h}: {} values", values.len());
        let (canvas, side) = (get("canvas"), get("side"));
        for (k, r) in &values {
            assert!(r[2] > r[0] && r[3] > r[1], "{w}x{h}: {k} is empty");
            assert!(
                r[0] >= 0.0 && r[2] <= f64::from(w),
                "{w}x{h}: {k} {r:?} cut off"
            );
            if w >= 1280 {
                assert!(
                    r[1] >= 0.0 && r[3] <= f64::from(h),
                    "{w}x{h}: {k} {r:?} below the fold"
                );
            }
        }
        if w >= 1280 {
            assert_eq!(v["page_scrolls"], false, "{w}x{h}: the page scrolls");
            assert!(side[0] >= canvas[2], "{w}x{h}: panel overlaps the map");
            assert!(side[2] <= f64::from(w), "{w}x{h}: panel cut off");
            assert!(
                canvas[2] - canvas[0] > f64::from(w) * 0.6,
                "{w}x{h}: small map"
            );
        } else {
            assert_eq!(v["hscroll"], false, "{w}x{h}: sideways scrolling");
            assert!(side[1] >= canvas[3], "{w}x{h}: panel not under the map");
            assert!(
                canvas[2] - canvas[0] > f64::from(w) * 0.8,
                "{w}x{h}: small map"
            );
        }
        // The screenshot, kept for people to look at.
        let shot = shots.join(format!("demo-replay-{w}x{h}.png"));
        let page = if w >= 500 {
            format!("file://{}#frame=last", run.join("replay.html").display())
        } else {
            // Narrower than a headless window can be: the page in a w x h iframe.
            let phone = run.join(format!("shot-{w}x{h}.html"));
            std::fs::write(
                &phone,
                format!(
                    r#"<!DOCTYPE html><html><body style="margin:0;background:#fff"><iframe src="replay.html#frame=last" width="{w}" height="{h}" style="border:0;display:block"></iframe></body></html>"#
                ),
            )
            .unwrap();
            format!("file://{}", phone.display())
        };
        let o = crate::common::output_within_limit(
            chrome(&chrome_bin, profile.path())
                .arg(format!("--window-size={},{h}", w.max(500)))
                .arg(format!("--screenshot={}", shot.display()))
                .arg(page),
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        eprintln!("{w}x{h}: screenshot {}", shot.display());
    }
}
