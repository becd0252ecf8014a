//! Scene-file text through the parser and every check. Any panic is a crash.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = ml_cpu::scene_file::parse(text);
    }
});
