//! Cooperative interruption of long computations.
//!
//! A caller that may want to stop a computation (the Python bindings, for Ctrl-C) runs it with a
//! [`Token`] installed on the computing thread ([`within`]). The long loops of the core call
//! [`check`] between units of work (a QR sweep, a product of the exponential, a problem of a
//! batch, a block of time steps), which returns [`Error::Interrupted`] once the token is
//! cancelled, so that the computation unwinds through its ordinary error path within a fraction of
//! a second. A parallel loop carries the token of the thread that started it to its items with
//! [`crate::platform::parallel::ParallelContext`]. Without a token, [`check`] is one thread-local load.

use crate::error::Error;
use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The cancellation flag of one computation, shared between the caller and the threads that
/// compute.
#[derive(Debug, Default)]
pub struct Token(AtomicBool);

impl Token {
    /// Asks the computation to stop at its next [`check`].
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`Token::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

thread_local! {
    static CURRENT: RefCell<Option<Arc<Token>>> = const { RefCell::new(None) };
}

/// `Err(Error::Interrupted)` if the token of this thread's computation was cancelled.
#[inline]
pub fn check() -> Result<(), Error> {
    let cancelled = CURRENT
        .try_with(|current| current.borrow().as_ref().is_some_and(|t| t.is_cancelled()))
        .unwrap_or(false);
    if cancelled {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

/// The token of this thread's computation, if it has one.
pub fn current() -> Option<Arc<Token>> {
    CURRENT
        .try_with(|current| current.borrow().clone())
        .ok()
        .flatten()
}

/// Runs `f` with `token` as this thread's token, restoring the previous one afterwards (also
/// when `f` panics).
pub fn within<T>(token: Option<Arc<Token>>, f: impl FnOnce() -> T) -> T {
    struct Restore(Option<Arc<Token>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let previous = self.0.take();
            let _ = CURRENT.try_with(|current| *current.borrow_mut() = previous);
        }
    }
    let previous = CURRENT
        .try_with(|current| current.replace(token))
        .ok()
        .flatten();
    let _restore = Restore(previous);
    f()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cancelled_token_stops_its_thread_only() {
        assert_eq!(check(), Ok(()));
        let token = Arc::new(Token::default());
        within(Some(token.clone()), || {
            assert_eq!(check(), Ok(()));
            token.cancel();
            assert_eq!(check(), Err(Error::Interrupted));
            std::thread::scope(|scope| {
                scope.spawn(|| assert_eq!(check(), Ok(())));
            });
        });
        assert_eq!(check(), Ok(()));
    }

    #[test]
    fn tokens_nest_and_are_restored() {
        let outer = Arc::new(Token::default());
        let inner = Arc::new(Token::default());
        inner.cancel();
        within(Some(outer.clone()), || {
            within(Some(inner), || assert_eq!(check(), Err(Error::Interrupted)));
            assert_eq!(check(), Ok(()));
            assert!(Arc::ptr_eq(&current().expect("outer token"), &outer));
        });
        assert!(current().is_none());
    }
}
