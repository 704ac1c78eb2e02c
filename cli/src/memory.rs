//! Peak resident memory of this process, per stage of `abgs run`.
//!
//! - **Overall peak**: Linux's own high-water mark (`VmHWM` in
//!   `/proc/self/status`), exact, and never reset: what the kernel reports to
//!   the parent at exit (`/usr/bin/time`, a batch scheduler's accounting)
//!   stays the run's true peak. (An earlier version reset the mark before
//!   each stage through `/proc/self/clear_refs`; that also lowered what
//!   `/usr/bin/time` reported to the peak of the last stages.)
//! - **Each stage's peak**: a sampling thread reads the resident size
//!   (`VmRSS`) every [`PERIOD`] and keeps the largest since the stage began;
//!   the readings at both ends of the stage count too. A spike shorter than
//!   the period can be missed by a stage's figure, never by the overall one.
//!
//! Cost: one small file read per period on a thread that otherwise sleeps
//! (about 27 µs per 10 ms read here: 0.3 % of one core). Elsewhere than Linux nothing is
//! measured and the report says `null`.

use serde_json::{json, Value};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// How often the sampling thread reads the resident size.
pub const PERIOD: Duration = Duration::from_millis(10);

/// A `kB` field of `/proc/self/status`, in bytes (`None` where unknown).
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// The peak resident set size so far, in bytes (`None` where unknown).
pub fn peak_rss_bytes() -> Option<u64> {
    status_bytes("VmHWM:")
}

/// The resident set size now, in bytes (`None` where unknown).
fn rss_bytes() -> Option<u64> {
    status_bytes("VmRSS:")
}

/// The sampling thread and the largest resident size it saw in the
/// current stage.
#[derive(Debug)]
struct Sampler {
    stage_max: Arc<AtomicU64>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Sampler {
    /// Starts sampling, the current stage's maximum seeded with `now`;
    /// `None` when the thread cannot be started.
    fn start(now: u64) -> Option<Sampler> {
        let stage_max = Arc::new(AtomicU64::new(now));
        let stop = Arc::new(AtomicBool::new(false));
        let (m, s) = (stage_max.clone(), stop.clone());
        let thread = std::thread::Builder::new()
            .name("abgs-memory".into())
            .spawn(move || {
                while !s.load(Ordering::Relaxed) {
                    if let Some(r) = rss_bytes() {
                        m.fetch_max(r, Ordering::Relaxed);
                    }
                    std::thread::park_timeout(PERIOD);
                }
            })
            .ok()?;
        Some(Sampler {
            stage_max,
            stop,
            thread: Some(thread),
        })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            t.thread().unpark();
            let _ = t.join();
        }
    }
}

/// Per-stage peaks of one run.
#[derive(Debug, Default)]
pub struct Meter {
    stages: Vec<(String, Option<u64>)>,
    overall: Option<u64>,
    sampler: Option<Sampler>,
}

impl Meter {
    /// A meter whose first stage starts now.
    pub fn new() -> Meter {
        Meter {
            overall: peak_rss_bytes(),
            sampler: rss_bytes().and_then(Sampler::start),
            ..Meter::default()
        }
    }

    /// Records the peak of the stage `name` that just ended and starts the
    /// next one.
    pub fn end_stage(&mut self, name: &str) {
        let now = rss_bytes().unwrap_or(0);
        // The next stage starts at the current size.
        let peak = self
            .sampler
            .as_ref()
            .map(|s| s.stage_max.swap(now, Ordering::Relaxed).max(now));
        // The kernel's mark and the sampled sizes are read from counters
        // kept apart (per CPU), so either can be a little ahead.
        self.overall = self.overall.max(peak_rss_bytes()).max(peak);
        self.stages.push((name.to_string(), peak));
    }

    /// The largest peak seen (bytes).
    pub fn overall(&self) -> Option<u64> {
        self.overall
    }

    /// The report's `memory` object: the overall peak, bytes per dense face
    /// (`dense_faces` > 0), each stage's sampled peak, and `per_stage`
    /// (false when the stages could not be sampled).
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
            "per_stage": self.sampler.is_some(),
            "stage_sample_period_ms": PERIOD.as_millis() as u64,
            "stage_peak_rss_bytes": stages,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(target_os = "linux")]
    fn a_stage_that_allocates_shows_in_its_peak_and_the_next_does_not() {
        let mut m = Meter::new();
        assert!(m.sampler.is_some());
        // Touch 64 MB so that it is resident, not only reserved.
        let big = std::hint::black_box(vec![1u8; 64 << 20]);
        assert_eq!(big.iter().map(|&b| b as usize).sum::<usize>(), 64 << 20);
        m.end_stage("allocate");
        drop(big);
        // This stage began with the 64 MB resident.
        m.end_stage("free");
        m.end_stage("after");
        let v = m.json(1000);
        let stage = |s: &str| v["stage_peak_rss_bytes"][s].as_u64().unwrap();
        assert!(
            stage("allocate") >= 64 << 20,
            "{} < 64 MB",
            stage("allocate")
        );
        assert!(stage("free") >= 64 << 20);
        assert!(
            stage("after") + (32 << 20) < stage("allocate"),
            "the stage after the free still counts it: {} against {}",
            stage("after"),
            stage("allocate")
        );
        let overall = v["peak_rss_bytes"].as_u64().unwrap();
        assert!(overall >= stage("allocate"));
        assert_eq!(
            v["peak_bytes_per_dense_face"].as_f64().unwrap(),
            overall as f64 / 1000.0
        );
        assert_eq!(v["per_stage"], json!(true));
    }
}
