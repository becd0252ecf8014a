//! The process environment a Vulkan driver reads, put right before the driver loads.
//!
//! Mesa's CPU driver (lavapipe, on llvmpipe) compiles shaders for the CPU's vector width —
//! 256 bits where the CPU has AVX, 128 without, or whatever `LP_NATIVE_VECTOR_WIDTH` says —
//! and keeps them in its on-disk shader cache, keyed by the CPU's features but not by that
//! width (Mesa 22.3). A program run once at 256 bits and again with
//! `LP_NATIVE_VECTOR_WIDTH=128` therefore loads vertex shaders that process 8 vertices a step
//! into a draw that allocated its vertex outputs for steps of 4: the shader writes up to four
//! vertices past the end of that allocation, and the process dies in JIT-compiled code
//! (a mesh of a few hundred vertices through the classic vertex pipeline is enough: the seed
//! scene's teapot, every fragment technique). With its own cache folder per width the driver
//! never sees code compiled for another width. On a CPU without AVX every run is at 128 bits
//! anyway, and the split costs at most one more cold cache.

use std::path::PathBuf;
use std::sync::Once;

/// The variable that sets llvmpipe's vector width.
const VECTOR_WIDTH: &str = "LP_NATIVE_VECTOR_WIDTH";
/// Mesa's shader cache folder (the driver adds `mesa_shader_cache` below it).
const CACHE_DIR: &str = "MESA_SHADER_CACHE_DIR";

/// Where Mesa's shader cache goes for the environment `var` describes: `None` when the cache
/// needs no folder of its own (no vector width forced, the cache switched off, or nowhere
/// to put it), else a folder for this vector width alone.
pub fn shader_cache_folder(var: impl Fn(&str) -> Option<String>) -> Option<PathBuf> {
    let width = var(VECTOR_WIDTH).filter(|w| !w.is_empty())?;
    let off = var("MESA_SHADER_CACHE_DISABLE").is_some_and(|v| matches!(v.to_ascii_lowercase().as_str(), "1" | "true" | "yes" | "y"));
    if off {
        return None;
    }
    // The width as part of a folder name: letters and digits only, no path separators.
    let width: String = width.chars().filter(char::is_ascii_alphanumeric).collect();
    let nonempty = |v: Option<String>| v.filter(|v| !v.is_empty()).map(PathBuf::from);
    let name = format!("lp-vector-width-{width}");
    if let Some(dir) = nonempty(var(CACHE_DIR)) {
        // A folder already of this width (a child of a process that chose it) stays.
        let chosen = dir.file_name().is_some_and(|n| n.to_string_lossy().ends_with(&name));
        return (!chosen).then(|| dir.join(name));
    }
    let cache_home = nonempty(var("XDG_CACHE_HOME")).or_else(|| nonempty(var("HOME")).map(|h| h.join(".cache")))?;
    Some(cache_home.join(format!("mesa-{name}")))
}

/// Give lavapipe's shader cache a folder per forced vector width (see the module's comment),
/// once per process; every Vulkan instance is made after it (`Context::new` calls it before
/// loading the driver), and `main` calls it first thing, before any thread starts: it sets an
/// environment variable, which is safe only while no other thread reads the environment
/// outside Rust's own lock — the driver, which no thread has loaded yet.
pub fn prepare() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let Some(folder) = shader_cache_folder(|name| std::env::var(name).ok()) else { return };
        // Mesa makes only the last folder of the path itself.
        if std::fs::create_dir_all(&folder).is_ok() {
            std::env::set_var(CACHE_DIR, &folder);
        } else {
            std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true");
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(vars: &[(&str, &str)]) -> Option<PathBuf> {
        shader_cache_folder(|name| vars.iter().find(|(n, _)| *n == name).map(|(_, v)| v.to_string()))
    }

    #[test]
    fn a_forced_vector_width_gets_a_cache_folder_of_its_own() {
        let home = [("HOME", "/home/u")];
        assert_eq!(folder(&home), None, "the driver's own width keeps the shared cache");
        assert_eq!(folder(&[("HOME", "/home/u"), (VECTOR_WIDTH, "")]), None);
        assert_eq!(folder(&[("HOME", "/home/u"), (VECTOR_WIDTH, "128")]), Some("/home/u/.cache/mesa-lp-vector-width-128".into()));
        let xdg = [("HOME", "/home/u"), ("XDG_CACHE_HOME", "/c"), (VECTOR_WIDTH, "256")];
        assert_eq!(folder(&xdg), Some("/c/mesa-lp-vector-width-256".into()));
        let own = [("HOME", "/home/u"), (CACHE_DIR, "/tmp/mine"), (VECTOR_WIDTH, "128")];
        assert_eq!(folder(&own), Some("/tmp/mine/lp-vector-width-128".into()), "a folder the user chose is split by width too");
        let chosen = [("HOME", "/home/u"), (CACHE_DIR, "/c/mesa-lp-vector-width-128"), (VECTOR_WIDTH, "128")];
        assert_eq!(folder(&chosen), None, "a folder of this width stays");
        let other = [("HOME", "/home/u"), (CACHE_DIR, "/c/mesa-lp-vector-width-256"), (VECTOR_WIDTH, "128")];
        assert_eq!(folder(&other), Some("/c/mesa-lp-vector-width-256/lp-vector-width-128".into()));
        assert_eq!(folder(&[(VECTOR_WIDTH, "128/../x")]), None, "no home, no folder");
        assert_eq!(folder(&[("HOME", "/h"), (VECTOR_WIDTH, "128/../x")]), Some("/h/.cache/mesa-lp-vector-width-128x".into()));
        for off in ["true", "1", "TRUE"] {
            assert_eq!(folder(&[("HOME", "/h"), (VECTOR_WIDTH, "128"), ("MESA_SHADER_CACHE_DISABLE", off)]), None);
        }
    }
}
