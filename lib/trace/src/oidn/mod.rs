//! Intel Open Image Denoise (OIDN 2.x), loaded at run time.
//!
//! Nothing links against OIDN at build time: [`Oidn::load`] finds the shared library (in
//! the order below), resolves the few C entry points used here and creates one CPU device.
//! [`shared`] does that once per process.
//!
//! # Search order
//! 1. [`ENV_LIBRARY`] (`PIS_OIDN_LIBRARY`): the library file or a directory holding
//!    [`LIBRARY_NAME`]; when set, it is the only candidate.
//! 2. [`LIBRARY_NAME`] through the system loader's search (`LD_LIBRARY_PATH`, ldconfig).
//! 3. `<pyoidn package>/oidn/lib/` [`LIBRARY_NAME`] (`pip install pyoidn`).
//!
//! # Threads
//! An [`Oidn`] may be shared between threads (rayon workers included). Calls on its device
//! are serialised by a mutex: one [`Oidn::denoise`] runs at a time, and OIDN spreads each
//! one over its own worker threads.

mod ffi;
mod locate;

use std::ffi::{c_char, c_int, c_void, CStr};
use std::path::{Path, PathBuf};
use std::ptr::{self, NonNull};
use std::sync::{Mutex, OnceLock, PoisonError};

pub use locate::{OidnUnavailable, ENV_LIBRARY, LIBRARY_NAME};

use ffi::Api;

/// Why a denoise call failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OidnError {
    /// The image's dimensions or buffers do not fit together; OIDN was not called.
    #[error("invalid denoiser input: {0}")]
    InvalidInput(String),
    /// OIDN reported an error (an `OIDNError` code and its message).
    #[error("OIDN error {code} ({}): {message}", ffi::error_name(*.code))]
    Device { code: i32, message: String },
}

/// An image to denoise.
///
/// Every buffer is interleaved RGB, `width * height * 3` values, rows from top to bottom.
#[derive(Debug, Clone, Copy)]
pub struct DenoiseImage<'a> {
    pub width: u32,
    pub height: u32,
    /// The noisy colour.
    pub color: &'a [f32],
    /// The surface albedo guide.
    pub albedo: Option<&'a [f32]>,
    /// The surface normal guide (components in [-1, 1]); needs `albedo`, as in OIDN.
    pub normal: Option<&'a [f32]>,
    /// `color` is radiance (high dynamic range) rather than display values in [0, 1].
    pub hdr: bool,
    /// The guides are free of noise.
    pub clean_aux: bool,
}

/// An OIDN device handle.
struct Device(NonNull<c_void>);

// SAFETY (and with it `Oidn: Send + Sync`, through the mutex): the handle is a pointer to OIDN's reference-counted device object, which is not
// tied to the thread that created it (OIDN's API is thread-safe and serialises work per
// device). The handle is only ever used with the mutex around it held, so no two threads
// use it at once, and per-thread error state is read on the thread that made the calls.
unsafe impl Send for Device {}

/// OIDN loaded, with one CPU device.
pub struct Oidn {
    /// The device; every call that uses it holds this lock.
    device: Mutex<Device>,
    /// The entry points, and the library they live in (kept loaded while `self` lives).
    api: Api,
    library: PathBuf,
    version: (i32, i32, i32),
}

impl Oidn {
    /// Finds and loads OIDN (see the module's search order), creates and commits a CPU
    /// device and checks that it is OIDN 2.x.
    pub fn load() -> Result<Oidn, OidnUnavailable> {
        let located = locate::locate()?;
        Oidn::with_library(located.api, located.path)
    }

    /// Creates the device on an already loaded library.
    fn with_library(api: Api, library: PathBuf) -> Result<Oidn, OidnUnavailable> {
        // SAFETY: the entry points come from an OIDN 2.x library held by `api`; a null
        // device is allowed in oidnGetDeviceError, to ask why creation failed.
        let handle = unsafe { (api.new_device)(ffi::DEVICE_TYPE_CPU) };
        let Some(handle) = NonNull::new(handle) else {
            let reason = match unsafe { take_error(&api, ptr::null_mut()) } {
                Some(error) => error.to_string(),
                None => "no device was created".to_string(),
            };
            return Err(OidnUnavailable::after_load(
                &library,
                format!("creating the CPU device: {reason}"),
            ));
        };
        let failure = |api: &Api, stage: &str, reason: String| {
            // SAFETY: `handle` is a live device created above and released only here.
            unsafe { (api.release_device)(handle.as_ptr()) };
            Err(OidnUnavailable::after_load(&library, format!("{stage}: {reason}")))
        };
        // SAFETY: `handle` is a live device of this library.
        unsafe { (api.commit_device)(handle.as_ptr()) };
        if let Some(error) = unsafe { take_error(&api, handle.as_ptr()) } {
            return failure(&api, "committing the CPU device", error.to_string());
        }
        let get = |name: &CStr| unsafe { (api.get_device_int)(handle.as_ptr(), name.as_ptr()) };
        let version = (get(c"versionMajor"), get(c"versionMinor"), get(c"versionPatch"));
        if let Some(error) = unsafe { take_error(&api, handle.as_ptr()) } {
            return failure(&api, "reading the version", error.to_string());
        }
        if version.0 != 2 {
            let found = format!("{}.{}.{}", version.0, version.1, version.2);
            return failure(&api, "unsupported version", format!("found {found}, need 2.x"));
        }
        Ok(Oidn { device: Mutex::new(Device(handle)), api, library, version })
    }

    /// The library's version, e.g. "2.5.1".
    pub fn version(&self) -> String {
        format!("{}.{}.{}", self.version.0, self.version.1, self.version.2)
    }

    /// The library file that was loaded.
    pub fn library(&self) -> &Path {
        &self.library
    }

    /// Denoises an RGB image (interleaved, `width * height * 3` values, rows top to bottom)
    /// with OIDN's "RT" filter and returns the denoised image in the same layout.
    ///
    /// `albedo` and `normal` are optional guides of the same shape (`normal` requires
    /// `albedo`, as OIDN does); `hdr` for radiance, `clean_aux` when the guides are
    /// noise-free. Mismatched lengths and empty images are errors, checked before OIDN is
    /// called.
    pub fn denoise(&self, image: &DenoiseImage) -> Result<Vec<f32>, OidnError> {
        let values = validate(image)?;
        let mut output = vec![0.0f32; values];
        let device = self.device.lock().unwrap_or_else(PoisonError::into_inner);
        let device = device.0.as_ptr();
        let api = &self.api;
        // SAFETY: `device` is this library's live device, used only under the lock held
        // above. Every image pointer covers `values` floats (checked by `validate`), stays
        // borrowed for the whole call and is read or written only during oidnExecuteFilter,
        // before the filter is released; OIDN only reads the inputs, so handing it a
        // `*mut` made from a shared slice is never used to write through.
        unsafe {
            // Errors are kept per thread; drop any left from an earlier call.
            let _ = take_error(api, device);
            let filter = (api.new_filter)(device, c"RT".as_ptr());
            let filter = match NonNull::new(filter) {
                Some(filter) => FilterGuard { api, filter },
                None => return Err(take_error(api, device).unwrap_or_else(no_filter)),
            };
            let (width, height) = (image.width as usize, image.height as usize);
            let set_image = |name: &CStr, data: *mut f32| {
                (api.set_shared_filter_image)(
                    filter.as_ptr(),
                    name.as_ptr(),
                    data.cast(),
                    ffi::FORMAT_FLOAT3,
                    width,
                    height,
                    0,
                    3 * size_of::<f32>(),
                    width * 3 * size_of::<f32>(),
                )
            };
            set_image(c"color", image.color.as_ptr().cast_mut());
            if let Some(albedo) = image.albedo {
                set_image(c"albedo", albedo.as_ptr().cast_mut());
                (api.set_filter_bool)(filter.as_ptr(), c"cleanAux".as_ptr(), image.clean_aux);
            }
            if let Some(normal) = image.normal {
                set_image(c"normal", normal.as_ptr().cast_mut());
            }
            set_image(c"output", output.as_mut_ptr());
            (api.set_filter_bool)(filter.as_ptr(), c"hdr".as_ptr(), image.hdr);
            (api.commit_filter)(filter.as_ptr());
            if let Some(error) = take_error(api, device) {
                return Err(error);
            }
            (api.execute_filter)(filter.as_ptr());
            if let Some(error) = take_error(api, device) {
                return Err(error);
            }
            drop(filter);
        }
        Ok(output)
    }
}

impl Drop for Oidn {
    fn drop(&mut self) {
        let device = self.device.get_mut().unwrap_or_else(PoisonError::into_inner);
        // SAFETY: the device is live and this is its only release; the library in
        // `self.api` is still loaded (fields drop after this runs).
        unsafe { (self.api.release_device)(device.0.as_ptr()) };
    }
}

/// Releases a filter when it goes out of scope, on every path out of a denoise call.
struct FilterGuard<'a> {
    api: &'a Api,
    filter: NonNull<c_void>,
}

impl FilterGuard<'_> {
    fn as_ptr(&self) -> ffi::FilterHandle {
        self.filter.as_ptr()
    }
}

impl Drop for FilterGuard<'_> {
    fn drop(&mut self) {
        // SAFETY: the filter is live and this is its only release.
        unsafe { (self.api.release_filter)(self.filter.as_ptr()) };
    }
}

fn no_filter() -> OidnError {
    OidnError::Device { code: 1, message: "the \"RT\" filter was not created".to_string() }
}

/// Takes the first pending error of `device` (null: of device creation) on this thread.
///
/// # Safety
/// `device` must be null or a live device of the library behind `api`.
unsafe fn take_error(api: &Api, device: ffi::DeviceHandle) -> Option<OidnError> {
    let mut message: *const c_char = ptr::null();
    // SAFETY: as promised by the caller; `message` is a valid place for the pointer.
    let code: c_int = unsafe { (api.get_device_error)(device, &mut message) };
    if code == ffi::ERROR_NONE {
        return None;
    }
    let message = if message.is_null() {
        String::new()
    } else {
        // SAFETY: OIDN returns a NUL-terminated string that stays valid until the next
        // call on the device; it is copied out at once.
        unsafe { CStr::from_ptr(message) }.to_string_lossy().into_owned()
    };
    Some(OidnError::Device { code, message })
}

/// Checks that the buffers fit the dimensions; returns the number of values per buffer.
fn validate(image: &DenoiseImage) -> Result<usize, OidnError> {
    let invalid = |message: String| Err(OidnError::InvalidInput(message));
    if image.width == 0 || image.height == 0 {
        return invalid(format!(
            "the image is {}x{}; both sides must be positive",
            image.width, image.height
        ));
    }
    let values = (image.width as usize)
        .checked_mul(image.height as usize)
        .and_then(|pixels| pixels.checked_mul(3))
        .filter(|values| values.checked_mul(size_of::<f32>()).is_some());
    let Some(values) = values else {
        return invalid(format!("a {}x{} image is too large", image.width, image.height));
    };
    let buffers =
        [("color", Some(image.color)), ("albedo", image.albedo), ("normal", image.normal)];
    for (name, buffer) in buffers {
        if let Some(buffer) = buffer {
            if buffer.len() != values {
                return invalid(format!(
                    "{name} has {} values; a {}x{} RGB image has {values}",
                    buffer.len(),
                    image.width,
                    image.height
                ));
            }
        }
    }
    if image.normal.is_some() && image.albedo.is_none() {
        return invalid("a normal guide needs an albedo guide too".to_string());
    }
    Ok(values)
}

/// For tests: the shared instance, or `None` after printing why `test` is skipped. Where
/// `PIS_REQUIRE_OIDN` is set (CI sets it) a missing library fails the test instead.
pub fn shared_or_skip(test: &str) -> Option<&'static Oidn> {
    match shared() {
        Ok(oidn) => Some(oidn),
        Err(reason) => {
            assert!(
                std::env::var_os("PIS_REQUIRE_OIDN").is_none(),
                "PIS_REQUIRE_OIDN is set but Open Image Denoise did not load: {reason}"
            );
            println!("skipped {test}: {reason}");
            None
        }
    }
}

/// OIDN loaded once per process: `Ok(&'static Oidn)`, or the reason it is unavailable
/// (found once too, and kept).
pub fn shared() -> Result<&'static Oidn, &'static OidnUnavailable> {
    static SHARED: OnceLock<Result<Oidn, OidnUnavailable>> = OnceLock::new();
    SHARED.get_or_init(Oidn::load).as_ref()
}

#[cfg(test)]
mod tests;
