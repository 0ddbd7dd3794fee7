//! A head-path CSV (`sequence --head-path`) → samples: no panic; a kept path is one the
//! sequence can follow (times increasing, every value finite and inside the limits); an
//! error is one line naming the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use seethru::scene::head_path::HeadPath;

fuzz_target!(|data: &[u8]| {
    match HeadPath::parse(data, "path.csv") {
        Ok(path) => {
            assert!(!path.samples.is_empty());
            assert_eq!(path.samples.len(), path.lines.len());
            for pair in path.samples.windows(2) {
                assert!(pair[0].0 < pair[1].0, "{pair:?}");
            }
            for &(t, eye) in &path.samples {
                assert!(t.is_finite() && eye.is_finite() && eye.abs().max_element() <= 1e6);
                // Between and beyond the samples the eye stays on the path's segments.
                for at in [t - 1.0, t, t + 0.25] {
                    assert!(path.at(at).is_finite(), "t = {at}");
                }
            }
            let far = glam::DAffine3::from_translation(glam::DVec3::new(9e5, 0.0, 0.0));
            if let Err(e) = path.check_in_world(&far) {
                let shown = format!("{e:#}");
                assert!(
                    shown.starts_with("path.csv:") && !shown.contains('\n'),
                    "{shown}"
                );
            }
        }
        Err(e) => {
            let shown = format!("{e:#}");
            assert!(
                shown.starts_with("path.csv") && !shown.contains('\n'),
                "{shown}"
            );
        }
    }
});
