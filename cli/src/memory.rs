//! Peak resident memory of this process, per stage of `abgs run`.
//!
//! Linux keeps the peak resident set size (`VmHWM` in `/proc/self/status`)
//! and lets a process reset it to the current size (writing `5` to
//! `/proc/self/clear_refs`, Linux ≥ 4.0). [`Meter`] resets it before each
//! stage and reads it after, so each stage gets its own peak; where the
//! reset is refused (an older kernel, a restricted container) the readings
//! are the running peak since the start, which still gives the overall peak.
//! Elsewhere than Linux nothing is measured and the report says `null`.
//! Each reading is one small file read: negligible against any stage.

use serde_json::{json, Value};

/// The peak resident set size so far, in bytes (`None` where unknown).
pub fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Resets the peak to the current resident size; false when refused.
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Per-stage peaks of one run.
#[derive(Debug, Default)]
pub struct Meter {
    stages: Vec<(String, Option<u64>)>,
    overall: Option<u64>,
    per_stage: bool,
}

impl Meter {
    /// A meter whose first stage starts now.
    pub fn new() -> Meter {
        Meter {
            overall: peak_rss_bytes(),
            per_stage: reset_peak(),
            ..Meter::default()
        }
    }

    /// Records the peak of the stage `name` that just ended and starts the
    /// next one.
    pub fn end_stage(&mut self, name: &str) {
        let peak = peak_rss_bytes();
        self.overall = self.overall.max(peak);
        self.stages.push((name.to_string(), peak));
        if self.per_stage {
            self.per_stage = reset_peak();
        }
    }

    /// The largest peak seen (bytes).
    pub fn overall(&self) -> Option<u64> {
        self.overall
    }

    /// The report's `memory` object: the overall peak, bytes per dense face
    /// (`dense_faces` > 0), and each stage's peak, with `per_stage` false
    /// when the readings are running peaks instead.
    pub fn json(&self, dense_faces: usize) -> Value {
        let stages: serde_json::Map<String, Value> = self
            .stages
            .iter()
            .map(|(k, v)| (k.clone(), json!(v)))
            .collect();
        json!({
            "peak_rss_bytes": self.overall,
            "peak_bytes_per_dense_face": self.overall
                .filter(|_| dense_faces > 0)
                .map(|b| b as f64 / dense_faces as f64),
            "per_stage": self.per_stage,
            "stage_peak_rss_bytes": stages,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(target_os = "linux")]
    fn a_stage_that_allocates_shows_in_its_peak() {
        let mut m = Meter::new();
        let before = peak_rss_bytes().unwrap();
        // Touch 64 MB so that it is resident, not only reserved, then free it.
        let big = std::hint::black_box(vec![1u8; 64 << 20]);
        assert_eq!(big.iter().map(|&b| b as usize).sum::<usize>(), 64 << 20);
        drop(big);
        m.end_stage("allocate");
        m.end_stage("after");
        let v = m.json(1000);
        let during = v["stage_peak_rss_bytes"]["allocate"].as_u64().unwrap();
        assert!(during >= before.max(64 << 20), "{during} < 64 MB");
        assert!(v["peak_rss_bytes"].as_u64().unwrap() >= during);
        let per_face = v["peak_bytes_per_dense_face"].as_f64().unwrap();
        assert_eq!(
            per_face,
            v["peak_rss_bytes"].as_u64().unwrap() as f64 / 1000.0
        );
        if v["per_stage"] == json!(true) {
            let after = v["stage_peak_rss_bytes"]["after"].as_u64().unwrap();
            assert!(
                after < during,
                "the reset did not take: {after} >= {during}"
            );
        }
    }
}
