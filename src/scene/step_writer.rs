//! Step files written on a thread of their own, in order, while the next step is solved.

use crate::scene::results::StepResult;
use crate::scene::run_error::RunError;
use crate::scene::writers::write_step;
use crate::scene::World;
use std::path::Path;
use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::{Scope, ScopedJoinHandle};
use std::time::Instant;

/// What the writer gives back: the steps kept for the writers after the loop, and the seconds
/// spent writing.
type Written = Result<(Vec<StepResult>, f64), RunError>;

/// A thread that writes each step handed to it with [`write_step`]. At most one step waits
/// while another is written, so memory holds at most three steps (solving, waiting, writing).
pub(crate) struct StepWriter<'scope> {
    sender: SyncSender<StepResult>,
    thread: ScopedJoinHandle<'scope, Written>,
}

impl<'scope> StepWriter<'scope> {
    /// Start the thread in `scope`; `steps_dir`, `digits` and `keep` are [`write_step`]'s.
    pub(crate) fn start<'env>(
        scope: &'scope Scope<'scope, 'env>,
        world: &'env World,
        steps_dir: &'env Path,
        digits: usize,
        keep: bool,
    ) -> Self {
        let (sender, receiver) = sync_channel::<StepResult>(1);
        let thread = scope.spawn(move || {
            let mut kept = Vec::new();
            let mut seconds = 0.0;
            for result in receiver {
                let t = Instant::now();
                kept.extend(write_step(world, steps_dir, result, digits, keep)?);
                seconds += t.elapsed().as_secs_f64();
            }
            Ok((kept, seconds))
        });
        StepWriter { sender, thread }
    }

    /// Hand `result` to the thread; false when it has stopped on an error, which
    /// [`StepWriter::finish`] returns.
    pub(crate) fn write(&self, result: StepResult) -> bool {
        self.sender.send(result).is_ok()
    }

    /// Wait for the steps handed over to be written; the kept steps and the seconds spent, or
    /// the first error.
    pub(crate) fn finish(self) -> Written {
        drop(self.sender);
        self.thread
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    }
}
