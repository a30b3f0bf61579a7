//! Cooperative interruption of long computations.
//!
//! A caller that may want to stop a computation (the Python bindings, for Ctrl-C) runs it with a
//! [`Token`] installed on the computing thread ([`within`]). The long loops of the core call
//! [`check`] between units of work (a QR sweep, a block of the Lyapunov solve, a problem of a
//! batch, a block of time steps), which returns [`Error::Interrupted`] once the token is
//! cancelled, so that the computation unwinds through its ordinary error path within a fraction of
//! a second. A parallel loop carries the token of the thread that started it to its items with
//! [`crate::platform::parallel::ParallelContext`]. Without a token, [`check`] is one
//! thread-local load.

use crate::error::Error;
use std::cell::Cell;
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

/// The token of a computation, as the threads that compute for it hold it: valid for as long as
/// it is installed by [`within`], whose caller borrows the token for that long.
#[derive(Debug, Clone, Copy)]
pub struct TokenRef(*const Token);

// SAFETY: a TokenRef points at a Token (Sync) that outlives every use of it: it is only read
// while installed by `within`, which borrows the token, on threads that the borrowing scope
// waits for (the items of a parallel loop inside that scope).
unsafe impl Send for TokenRef {}
// SAFETY: as above.
unsafe impl Sync for TokenRef {}

thread_local! {
    static CURRENT: Cell<Option<TokenRef>> = const { Cell::new(None) };
}

/// `Err(Error::Interrupted)` if the token of this thread's computation was cancelled.
#[inline]
pub fn check() -> Result<(), Error> {
    let current = CURRENT.try_with(Cell::get).ok().flatten();
    // SAFETY: an installed TokenRef is valid (see `TokenRef`).
    match current.map(|token| unsafe { &*token.0 }.is_cancelled()) {
        Some(true) => Err(Error::Interrupted),
        _ => Ok(()),
    }
}

/// The token of this thread's computation, if it has one, for the items of a parallel loop
/// started within that computation (to be installed with [`within_ref`]).
pub fn current() -> Option<TokenRef> {
    CURRENT.try_with(Cell::get).ok().flatten()
}

/// Runs `f` with `token` as this thread's token, restoring the previous one afterwards (also
/// when `f` panics).
pub fn within<T>(token: &Token, f: impl FnOnce() -> T) -> T {
    within_ref(Some(TokenRef(token)), f)
}

/// [`within`] for the token of an enclosing computation ([`current`]), or none.
pub fn within_ref<T>(token: Option<TokenRef>, f: impl FnOnce() -> T) -> T {
    struct Restore(Option<TokenRef>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let _ = CURRENT.try_with(|current| current.set(self.0));
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
        let token = Token::default();
        within(&token, || {
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
        let outer = Token::default();
        let inner = Token::default();
        inner.cancel();
        within(&outer, || {
            within(&inner, || assert_eq!(check(), Err(Error::Interrupted)));
            assert_eq!(check(), Ok(()));
            let carried = current();
            std::thread::scope(|scope| {
                scope.spawn(|| {
                    within_ref(carried, || {
                        assert_eq!(check(), Ok(()));
                        outer.cancel();
                        assert_eq!(check(), Err(Error::Interrupted));
                    })
                });
            });
        });
        assert!(current().is_none());
    }
}
