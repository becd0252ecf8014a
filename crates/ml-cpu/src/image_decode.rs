//! Image decoders are others' code: every decode and header read goes through
//! `guarded_decode`, so that a file they cannot read is one error line, not a crash.

thread_local! {
    /// Whether this thread is inside `guarded_decode` (its panics are answered there).
    static DECODING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// `decode`'s result, or None where it panicked: the image decoders are others' code, and a
/// file they cannot read must be one error line, not a crash (fuzzing found a JPEG whose
/// decoder multiplies past u32 — a panic where overflow checks are on, as in debug builds).
/// Its panic message is not printed: the panic hook stays quiet on a thread inside this call
/// and hands every other panic to the hook before it.
pub fn guarded_decode<T>(decode: impl FnOnce() -> T) -> Option<T> {
    static QUIET_HOOK: std::sync::Once = std::sync::Once::new();
    QUIET_HOOK.call_once(|| {
        let before = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !DECODING.with(std::cell::Cell::get) {
                before(info);
            }
        }));
    });
    DECODING.with(|d| d.set(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode)).ok();
    DECODING.with(|d| d.set(false));
    result
}
