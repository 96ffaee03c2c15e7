//! A request to stop a run (SIGINT, SIGTERM), passed down to the loops that can take long:
//! Newton iterations, contact iterations, fracture events, drawing and writing.

use std::sync::atomic::{AtomicBool, Ordering};

/// Whether a run has been asked to stop: a flag the caller owns (the CLI raises it from its
/// signal handler), read by the solvers between iterations. The default never fires. It is a
/// handle, not a setting: two handles compare equal whatever they point at, so settings that
/// carry one compare by their values.
#[derive(Clone, Copy, Debug, Default)]
pub struct Interrupt {
    flag: Option<&'static AtomicBool>,
}

impl Interrupt {
    /// An interrupt raised by setting `flag` (a `static` the caller owns, or a leaked box).
    pub fn on(flag: &'static AtomicBool) -> Self {
        Interrupt { flag: Some(flag) }
    }

    /// Whether the stop has been asked for.
    pub fn is_raised(&self) -> bool {
        self.flag.is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// Ask for the stop (what the signal handler does).
    pub fn raise(&self) {
        if let Some(f) = self.flag {
            f.store(true, Ordering::SeqCst);
        }
    }
}

impl PartialEq for Interrupt {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raised_only_after_raise_and_never_by_default() {
        let flag: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(false)));
        let i = Interrupt::on(flag);
        assert!(!i.is_raised());
        assert!(!Interrupt::default().is_raised());
        i.raise();
        assert!(i.is_raised() && flag.load(Ordering::Relaxed));
        Interrupt::default().raise();
        assert!(!Interrupt::default().is_raised());
    }
}
