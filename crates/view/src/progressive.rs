//! The CPU backend's progression: a coarse frame while the camera moves, the full resolution
//! once it stops, then the anti-aliased frame — one job at a time, newest view first.

/// How much of a view a CPU frame renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// A quarter of the width and height, one sample per pixel.
    Coarse,
    /// Full resolution, the scene's samples.
    Full,
    /// Full resolution, the viewer's still-frame samples (when they are more).
    Refined,
}

/// The side of a coarse frame relative to the window's.
pub const COARSE_DIVISOR: u32 = 4;

impl Level {
    /// The image size of this level for a `width × height` window.
    pub fn size(self, (width, height): (u32, u32)) -> (u32, u32) {
        match self {
            Level::Coarse => (
                width.div_ceil(COARSE_DIVISOR).max(1),
                height.div_ceil(COARSE_DIVISOR).max(1),
            ),
            Level::Full | Level::Refined => (width.max(1), height.max(1)),
        }
    }
}

/// A job to give the worker: render the view of `generation` at `level`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Job {
    pub generation: u64,
    pub level: Level,
}

/// Which frame to render next. Every change of the view (camera, settings, size) is a new
/// generation; the worker holds at most one job, so a moving camera's frames never queue up.
#[derive(Clone, Copy, Debug)]
pub struct Progression {
    generation: u64,
    in_flight: bool,
    shown: Option<Job>,
    /// Whether a still view is refined (the still-frame samples exceed the scene's).
    pub refine: bool,
}

impl Progression {
    pub fn new(refine: bool) -> Self {
        Self {
            generation: 0,
            in_flight: false,
            shown: None,
            refine,
        }
    }

    /// The view changed: what is shown or rendering is out of date.
    pub fn changed(&mut self) {
        self.generation += 1;
    }

    /// The current view's generation.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The worker finished `job`; returns whether its frame is of the current view. A frame of
    /// an older view is still the newest picture there is (a moving camera's frames are all of
    /// views it has left), so the caller shows it either way; only a current one counts toward
    /// the view's progression.
    pub fn finished(&mut self, job: Job) -> bool {
        self.in_flight = false;
        let current = job.generation == self.generation;
        if current {
            self.shown = Some(job);
        }
        current
    }

    /// The last level of a still view.
    pub fn final_level(&self) -> Level {
        if self.refine {
            Level::Refined
        } else {
            Level::Full
        }
    }

    /// Whether the current view is shown at its final level.
    pub fn is_final(&self) -> bool {
        self.shown
            == Some(Job {
                generation: self.generation,
                level: self.final_level(),
            })
    }

    /// The next job to start, if the worker is free and there is one: a new view starts coarse;
    /// a view that stays still (`moving` false) then goes to full resolution and refinement.
    pub fn next(&mut self, moving: bool) -> Option<Job> {
        if self.in_flight {
            return None;
        }
        let level = match self.shown {
            Some(job) if job.generation == self.generation => {
                if moving {
                    return None;
                }
                match job.level {
                    Level::Coarse => Level::Full,
                    Level::Full if self.refine => Level::Refined,
                    _ => return None,
                }
            }
            _ => Level::Coarse,
        };
        self.in_flight = true;
        Some(Job {
            generation: self.generation,
            level,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the worker at once: takes the next job and finishes it.
    fn step(p: &mut Progression, moving: bool) -> Option<Level> {
        let job = p.next(moving)?;
        assert!(p.next(moving).is_none(), "one job at a time");
        p.finished(job);
        Some(job.level)
    }

    #[test]
    fn a_still_view_goes_coarse_full_refined_then_stops() {
        let mut p = Progression::new(true);
        assert_eq!(step(&mut p, false), Some(Level::Coarse));
        assert!(!p.is_final());
        assert_eq!(step(&mut p, false), Some(Level::Full));
        assert_eq!(step(&mut p, false), Some(Level::Refined));
        assert!(p.is_final());
        assert_eq!(step(&mut p, false), None);
        let mut q = Progression::new(false);
        assert_eq!(step(&mut q, false), Some(Level::Coarse));
        assert_eq!(step(&mut q, false), Some(Level::Full));
        assert!(q.is_final());
        assert_eq!(step(&mut q, false), None);
    }

    #[test]
    fn a_moving_view_stays_coarse_and_refines_when_it_stops() {
        let mut p = Progression::new(true);
        for _ in 0..3 {
            p.changed();
            assert_eq!(step(&mut p, true), Some(Level::Coarse));
            assert_eq!(step(&mut p, true), None, "nothing more while moving");
        }
        assert_eq!(step(&mut p, false), Some(Level::Full));
    }

    #[test]
    fn a_frame_of_an_old_view_does_not_advance_the_new_one() {
        let mut p = Progression::new(false);
        let job = p.next(false).unwrap();
        p.changed();
        assert!(!p.finished(job), "stale");
        let job = p.next(false).unwrap();
        assert_eq!(job.level, Level::Coarse);
        assert_eq!(job.generation, p.generation());
        assert!(p.finished(job));
    }

    #[test]
    fn coarse_frames_are_a_quarter_of_each_side() {
        assert_eq!(Level::Coarse.size((640, 360)), (160, 90));
        assert_eq!(Level::Coarse.size((3, 1)), (1, 1));
        assert_eq!(Level::Full.size((640, 360)), (640, 360));
    }
}
