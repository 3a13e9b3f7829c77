//! Opening the GPU without `XDG_RUNTIME_DIR` gives the process a private one first, so
//! Mesa's Vulkan drivers do not print "XDG_RUNTIME_DIR is invalid or not set". Its own
//! test binary: it changes the process environment.

#[cfg(unix)]
#[test]
fn gpu_new_sets_a_private_xdg_runtime_dir_where_none_is_set() {
    use std::os::unix::fs::PermissionsExt;
    std::env::remove_var("XDG_RUNTIME_DIR");
    // Whether or not an adapter exists, the directory is set before the instance is made.
    let _ = pis_play::Gpu::new();
    let dir = std::env::var_os("XDG_RUNTIME_DIR").expect("XDG_RUNTIME_DIR set");
    let meta = std::fs::metadata(&dir).expect("the directory exists");
    assert!(meta.is_dir());
    assert_eq!(meta.permissions().mode() & 0o077, 0, "{dir:?} is private");
}
