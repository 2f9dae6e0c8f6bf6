//! Third-party decoders (OpenEXR, PNG) run so that a panic inside one becomes an error naming the
//! file instead of ending the process: bad input never panics fray, even where a dependency
//! does. The decoder must run on the calling thread — a panic on a thread pool's worker aborts
//! the process before it can be caught — so callers ask their decoder for sequential decoding.

use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `decode` on this thread; a panic inside it is returned as `Err`, "`decoder` failed on
/// this file: " and its message (the default panic hook has already printed it to standard
/// error). Nothing `decode` borrows is used after a panic: the caller returns the error.
pub fn contain_panic<T>(decoder: &str, decode: impl FnOnce() -> T) -> Result<T, String> {
    catch_unwind(AssertUnwindSafe(decode)).map_err(|payload| {
        let message = payload
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| payload.downcast_ref::<&str>().map(|s| (*s).to_owned()))
            .unwrap_or_else(|| "a panic without a message".to_owned());
        format!("{decoder} failed on this file: {message}")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_its_message_and_a_value_passes() {
        assert_eq!(contain_panic("d", || 7), Ok(7));
        let index = std::hint::black_box(9);
        let e = contain_panic("the decoder", || [1, 2, 3][index]).unwrap_err();
        assert!(
            e.starts_with("the decoder failed on this file: index out of bounds"),
            "{e}"
        );
        assert_eq!(
            contain_panic("d", || -> u8 { panic!("plain") }),
            Err("d failed on this file: plain".to_owned())
        );
    }
}
