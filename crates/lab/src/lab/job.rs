//! A lab run driven a step at a time by an application's frame loop (the viewer's measure
//! panel, natively and in the page): [`run_async`] on a device of its own, polled by
//! [`LabJob::advance`] once per displayed frame. In the page the run's readbacks finish
//! only when control returns to the browser, so the job cannot be blocked on; natively
//! it could be, but then the window would freeze for the whole run.

use std::cell::RefCell;
use std::future::Future;
use std::pin::Pin;
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::task::{Context, Poll, Wake, Waker};
use web_time::{Duration, Instant};

use anyhow::{Context as _, bail};

use manylights::LoadedScene;
use manylights::gpu::{AdapterRequest, GpuContext, wgpu};

use super::matrix::BenchMatrix;
use super::results::{BenchReport, BenchResult};
use super::run::run_async;

/// How far a job has come.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JobProgress {
    pub done: usize,
    pub total: usize,
    /// The last configuration measured, as one line.
    pub last: String,
}

/// A lab run in progress.
pub struct LabJob {
    run: Pin<Box<dyn Future<Output = anyhow::Result<BenchReport>>>>,
    progress: Rc<RefCell<JobProgress>>,
    stop: Arc<AtomicBool>,
    woken: Arc<WokenFlag>,
}

/// A waker that only records that it was woken: the job is polled again in the same
/// frame while it is (it yielded after a frame), and left for the next frame while it
/// waits for the GPU.
struct WokenFlag(AtomicBool);

impl Wake for WokenFlag {
    fn wake(self: Arc<Self>) {
        self.0.store(true, Ordering::SeqCst);
    }
    fn wake_by_ref(self: &Arc<Self>) {
        self.0.store(true, Ordering::SeqCst);
    }
}

impl LabJob {
    /// Starts measuring `matrix` on `scene` (every scene of the matrix is this one; it is
    /// named `scene_name` in the report) with a new device chosen as `request` asks on
    /// `instance`: the job's device is its own, so its frames never wait behind the
    /// application's.
    pub fn start(
        instance: wgpu::Instance,
        request: AdapterRequest,
        scene: LoadedScene,
        scene_name: String,
        mut matrix: BenchMatrix,
    ) -> Self {
        matrix.scenes = vec![scene_name.clone()];
        let progress = Rc::new(RefCell::new(JobProgress {
            total: matrix.configurations().map_or(0, |c| c.len()),
            ..JobProgress::default()
        }));
        let stop = Arc::new(AtomicBool::new(false));
        let run = {
            let (progress, stop) = (Rc::clone(&progress), Arc::clone(&stop));
            async move {
                let context = GpuContext::headless_async(instance, &request)
                    .await
                    .context("creating the lab's GPU device")?;
                let mut load_scene = |spec: &str| {
                    if spec != scene_name {
                        bail!(
                            "the measure panel measures the scene shown ({scene_name}), not {spec}"
                        );
                    }
                    Ok(scene.clone())
                };
                let mut on_result = |result: &BenchResult, done: usize, total: usize| {
                    *progress.borrow_mut() = JobProgress {
                        done,
                        total,
                        last: result.summary_line(),
                    };
                };
                run_async(&matrix, context, &mut load_scene, &stop, &mut on_result).await
            }
        };
        Self {
            run: Box::pin(run),
            progress,
            stop,
            woken: Arc::new(WokenFlag(AtomicBool::new(false))),
        }
    }

    /// Runs the job for at most about `budget` (it yields after every frame it renders);
    /// its report once it ended.
    pub fn advance(&mut self, budget: Duration) -> Option<anyhow::Result<BenchReport>> {
        let started = Instant::now();
        let waker = Waker::from(Arc::clone(&self.woken));
        let mut context = Context::from_waker(&waker);
        loop {
            self.woken.0.store(false, Ordering::SeqCst);
            if let Poll::Ready(report) = self.run.as_mut().poll(&mut context) {
                return Some(report);
            }
            // Waiting for the GPU (the page's map callbacks), or out of time this frame.
            if !self.woken.0.load(Ordering::SeqCst) || started.elapsed() >= budget {
                return None;
            }
        }
    }

    pub fn progress(&self) -> JobProgress {
        self.progress.borrow().clone()
    }

    /// Asks the run to stop after the configuration it is measuring; its report keeps
    /// what was measured and says it was interrupted.
    pub fn stop(&self) {
        self.stop.store(true, Ordering::SeqCst);
    }
}

impl std::fmt::Debug for LabJob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LabJob")
            .field("progress", &self.progress())
            .finish_non_exhaustive()
    }
}
