//! Renderer calls on different threads take turns where the driver crashes when two contexts
//! work at once: on Mesa 22.3's llvmpipe, one context's `glClear` freed memory another
//! context's flush then read (docs/drivers.md, item 20). [`Turn`] takes and gives it back.

use std::sync::{Condvar, Mutex, MutexGuard};
use std::thread::ThreadId;

/// Whether calls on contexts of the driver `renderer` (`GL_RENDERER`) take turns.
pub(crate) fn needed_by(renderer: &str) -> bool {
    renderer.contains("llvmpipe")
}

/// The thread whose calls hold the turn, and how many of them: nested calls, or calls of
/// several renderers on one thread, hold it once.
struct Holder {
    thread: Option<ThreadId>,
    calls: u32,
}

static HOLDER: Mutex<Holder> = Mutex::new(Holder {
    thread: None,
    calls: 0,
});

/// Signalled when a thread gives the turn back.
static GIVEN_BACK: Condvar = Condvar::new();

fn lock() -> MutexGuard<'static, Holder> {
    HOLDER.lock().unwrap_or_else(|e| e.into_inner())
}

/// Waits until no other thread holds the turn, then holds it for this thread (once more).
/// Pair it with [`give_back`] on the same thread, in a way a panic cannot skip ([`Turn`]).
fn take() {
    let here = std::thread::current().id();
    let mut holder = lock();
    while holder.thread.is_some_and(|t| t != here) {
        holder = GIVEN_BACK.wait(holder).unwrap_or_else(|e| e.into_inner());
    }
    holder.thread = Some(here);
    holder.calls += 1;
}

/// Gives back a turn [`take`] held for this thread; the last one lets other threads in.
fn give_back() {
    let mut holder = lock();
    debug_assert_eq!(holder.thread, Some(std::thread::current().id()));
    holder.calls = holder.calls.saturating_sub(1);
    if holder.calls == 0 {
        holder.thread = None;
        GIVEN_BACK.notify_all();
    }
}

/// Runs `f` with this thread's turn let go, if it holds one, then takes it back (as many times
/// as it was held). For CPU work inside a call that waits for other threads: rayon's pool, whose
/// workers may be waiting for the turn in renderer calls of their own (a deadlock).
pub(crate) fn let_go_while<T>(f: impl FnOnce() -> T) -> T {
    let here = std::thread::current().id();
    let calls = {
        let mut holder = lock();
        if holder.thread != Some(here) {
            drop(holder);
            return f();
        }
        let calls = std::mem::take(&mut holder.calls);
        holder.thread = None;
        GIVEN_BACK.notify_all();
        calls
    };
    /// Takes the turn back when dropped, panics included: the call's guards give it back.
    struct TakeBack(u32);
    impl Drop for TakeBack {
        fn drop(&mut self) {
            for _ in 0..self.0 {
                take();
            }
        }
    }
    let _take_back = TakeBack(calls);
    f()
}

/// A turn this thread holds (none where none was needed), given back when dropped, panics
/// included, unless [`Turn::keep`] leaves it for a later [`give_back`].
pub(crate) struct Turn(bool);

impl Turn {
    /// Takes the turn where `needed` ([`take`]).
    pub(crate) fn take_if(needed: bool) -> Turn {
        if needed {
            take();
        }
        Turn(needed)
    }

    /// The turn [`take`] held earlier where `held`, to be given back by this guard.
    pub(crate) fn held(held: bool) -> Turn {
        Turn(held)
    }

    /// Keeps the turn past this guard: a later [`give_back`] or [`Turn::held`] gives it back.
    pub(crate) fn keep(mut self) {
        self.0 = false;
    }
}

impl Drop for Turn {
    fn drop(&mut self) {
        if self.0 {
            give_back();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::{mpsc, Arc};
    use std::time::Duration;

    #[test]
    fn only_llvmpipe_takes_turns() {
        assert!(super::needed_by("llvmpipe (LLVM 15.0.6, 256 bits)"));
        assert!(!super::needed_by("softpipe"));
        assert!(!super::needed_by("Google SwiftShader"));
    }

    /// A turn's guard gives it back when a panic unwinds past it: other threads do not wait
    /// for good.
    #[test]
    fn a_panic_gives_the_turn_back() {
        let caught = std::thread::spawn(|| {
            std::panic::catch_unwind(|| {
                let _turn = super::Turn::take_if(true);
                panic!("a bug inside a renderer call");
            })
            .is_err()
        })
        .join()
        .unwrap();
        assert!(caught);
        let (taken, wait_taken) = mpsc::channel();
        std::thread::spawn(move || {
            let _turn = super::Turn::take_if(true);
            taken.send(()).unwrap();
        });
        assert!(
            wait_taken.recv_timeout(Duration::from_secs(60)).is_ok(),
            "the panicking thread kept the turn"
        );
    }

    /// A second thread's turn waits for the first thread's last nested call to give its back.
    #[test]
    fn another_thread_waits_for_the_turn_and_this_one_nests() {
        let (entered, wait_entered) = mpsc::channel();
        let given = Arc::new(AtomicBool::new(false));
        let first = {
            let given = given.clone();
            std::thread::spawn(move || {
                super::take();
                super::take();
                entered.send(()).unwrap();
                super::give_back();
                // The other thread is waiting, or about to: give it time to go wrongly.
                std::thread::sleep(Duration::from_millis(100));
                given.store(true, Ordering::SeqCst);
                super::give_back();
            })
        };
        wait_entered.recv().unwrap();
        super::take();
        let after = given.load(Ordering::SeqCst);
        super::give_back();
        first.join().unwrap();
        assert!(after, "the turn was taken while another thread held it");
    }
}
