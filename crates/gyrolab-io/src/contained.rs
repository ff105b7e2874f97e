//! Panics of third-party readers, contained: the last line of defence where a crate cannot be
//! kept from panicking on a damaged file by checking the file first (docs/FUZZING.md lists
//! where). The panic becomes a message in words; the panic hook stays quiet for it (the
//! previous hook still reports every other panic).

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};

thread_local! {
    /// Whether this thread is inside [`contain`].
    static CONTAINED: Cell<bool> = const { Cell::new(false) };
}

static HOOK: std::sync::Once = std::sync::Once::new();

/// Runs `f`; a panic inside it is returned as its message (shortened), not printed.
///
/// ```
/// let r: Result<u8, String> = gyrolab_io::contained::contain(|| panic!("index out of range"));
/// assert_eq!(r.unwrap_err(), "index out of range");
/// assert_eq!(gyrolab_io::contained::contain(|| 7), Ok(7));
/// ```
pub fn contain<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !CONTAINED.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let outer = CONTAINED.with(|c| c.replace(true));
    let r = catch_unwind(AssertUnwindSafe(f));
    CONTAINED.with(|c| c.set(outer));
    r.map_err(|payload| {
        let text = if let Some(s) = payload.downcast_ref::<&str>() {
            (*s).to_string()
        } else if let Some(s) = payload.downcast_ref::<String>() {
            s.clone()
        } else {
            "an internal error".to_string()
        };
        crate::text::short_message(&text)
    })
}
