//! The CPU backend off the UI thread: a worker that renders one job at a time through
//! `fray-render` (the same frames `fray render --backend cpu` makes) and wakes the window when
//! a frame is ready.

use crate::progressive::Job;
use fray_core::Frame;
use fray_render::{RenderOptions, Renderer};
use fray_scene::Scene;
use std::sync::mpsc::{Receiver, Sender, channel};
use std::thread::JoinHandle;

/// What the worker renders: `scene` (its camera the view's) with `options`.
#[derive(Debug)]
pub struct Request {
    pub job: Job,
    pub scene: Scene,
    pub options: RenderOptions,
}

/// A finished job: its frame, or why it failed.
#[derive(Debug)]
pub struct Done {
    pub job: Job,
    pub frame: Result<Frame, String>,
}

/// The worker thread and its two channels.
#[derive(Debug)]
pub struct Worker {
    requests: Option<Sender<Request>>,
    done: Receiver<Done>,
    thread: Option<JoinHandle<()>>,
}

impl Worker {
    /// Starts the worker; `wake` is called (from its thread) after each finished job.
    pub fn start(wake: impl Fn() + Send + 'static) -> Self {
        let (requests, inbox) = channel::<Request>();
        let (outbox, done) = channel();
        let thread = std::thread::Builder::new()
            .name("fray-view cpu".into())
            .spawn(move || {
                for request in inbox {
                    let frame = Renderer::new(request.options)
                        .render(&request.scene)
                        .map_err(|e| e.to_string());
                    if outbox
                        .send(Done {
                            job: request.job,
                            frame,
                        })
                        .is_err()
                    {
                        break;
                    }
                    wake();
                }
            })
            .ok();
        Self {
            requests: Some(requests),
            done,
            thread,
        }
    }

    /// Hands the worker a job (it holds at most one: `Progression` says when).
    pub fn send(&self, request: Request) -> Result<(), String> {
        match (&self.requests, &self.thread) {
            (Some(tx), Some(_)) => tx
                .send(request)
                .map_err(|_| "the CPU worker stopped".to_owned()),
            _ => Err("the CPU worker could not start".to_owned()),
        }
    }

    /// A finished job, if one is waiting.
    pub fn try_done(&self) -> Option<Done> {
        self.done.try_recv().ok()
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // Closing the channel ends the worker's loop after its current job.
        self.requests = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
