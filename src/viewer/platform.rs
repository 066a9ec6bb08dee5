//! The process environment the window needs, set in `main` before any
//! thread starts.
//!
//! At every start on X11 without `XDG_RUNTIME_DIR`, "error: XDG_RUNTIME_DIR
//! is invalid or not set in the environment." was printed twice. It comes
//! from neither winit nor egui: Mesa's Vulkan device-selection layer
//! (`VK_LAYER_MESA_device_select`, an implicit layer) calls libwayland's
//! `wl_display_connect` while wgpu enumerates the adapters, because wgpu
//! enables `VK_KHR_wayland_surface` on every instance; libwayland prints
//! the line when it finds no runtime directory. With no Wayland session
//! and no runtime directory that probe can only fail, so the layer is
//! switched off there with its documented variable (`NODEVICE_SELECT=1`)
//! — unless the user chose a device (`DRI_PRIME`, `MESA_VK_DEVICE_SELECT`),
//! which only that layer honours.

use std::ffi::OsString;
use std::path::Path;

/// Whether the device-selection layer's Wayland probe is bound to fail
/// and print, given the environment `var`.
fn probe_fails(var: impl Fn(&str) -> Option<OsString>) -> bool {
    let set = |k: &str| var(k).is_some_and(|v| !v.is_empty());
    let runtime_ok = var("XDG_RUNTIME_DIR").is_some_and(|d| {
        let p = Path::new(&d);
        p.is_absolute() && p.is_dir()
    });
    set("DISPLAY")
        && !set("WAYLAND_DISPLAY")
        && !set("WAYLAND_SOCKET")
        && !runtime_ok
        && !set("DRI_PRIME")
        && !set("MESA_VK_DEVICE_SELECT")
        && var("NODEVICE_SELECT").is_none()
}

/// Turns the Wayland probe off where it can only fail (see the module's
/// documentation). Call before any thread is started.
pub fn quiet_wayland_probe() {
    if probe_fails(|k| std::env::var_os(k)) {
        // SAFETY: `set_var` is unsafe because another thread could read
        // the environment at the same time. This runs first thing in
        // `main`, after argument parsing and before any thread (render
        // thread, rayon pool, event loop, Ctrl-C handler) exists. It is
        // needed because the Vulkan loader reads the switch from the
        // environment of this process when wgpu creates its instance.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env(pairs: &[(&str, &str)]) -> impl Fn(&str) -> Option<OsString> {
        let v: Vec<(String, String)> = pairs.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        move |k| v.iter().find(|(n, _)| n == k).map(|(_, x)| x.into())
    }

    #[test]
    fn the_probe_is_off_only_on_x11_without_a_runtime_directory() {
        let tmp = std::env::temp_dir();
        let tmp = tmp.to_str().unwrap();
        assert!(probe_fails(env(&[("DISPLAY", ":0")])));
        assert!(probe_fails(env(&[("DISPLAY", ":0"), ("XDG_RUNTIME_DIR", "relative")])));
        assert!(probe_fails(env(&[
            ("DISPLAY", ":0"),
            ("XDG_RUNTIME_DIR", "/no/such/dir")
        ])));
        assert!(!probe_fails(env(&[("DISPLAY", ":0"), ("XDG_RUNTIME_DIR", tmp)])));
        assert!(!probe_fails(env(&[
            ("DISPLAY", ":0"),
            ("WAYLAND_DISPLAY", "wayland-0")
        ])));
        assert!(!probe_fails(env(&[])), "no display: nothing to quiet");
        assert!(!probe_fails(env(&[("DISPLAY", ":0"), ("DRI_PRIME", "1")])));
        assert!(!probe_fails(env(&[("DISPLAY", ":0"), ("NODEVICE_SELECT", "0")])));
    }
}
