//! The OIDN 2.x C entry points used here, resolved by name from a loaded library.
//!
//! Signatures follow `include/OpenImageDenoise/oidn.h` of OIDN 2.x (the `...Bool`/`...Int`
//! parameter setters of the 2.0 release and later).

use std::ffi::{c_char, c_int, c_void};

use libloading::Library;

/// `OIDNDevice`: an opaque, reference-counted device handle.
pub(crate) type DeviceHandle = *mut c_void;
/// `OIDNFilter`: an opaque, reference-counted filter handle.
pub(crate) type FilterHandle = *mut c_void;

/// `OIDN_DEVICE_TYPE_CPU` of `OIDNDeviceType`.
pub(crate) const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_ERROR_NONE` of `OIDNError`.
pub(crate) const ERROR_NONE: c_int = 0;
/// `OIDN_FORMAT_FLOAT3` of `OIDNFormat`.
pub(crate) const FORMAT_FLOAT3: c_int = 3;

/// The name of an `OIDNError` code.
pub(crate) fn error_name(code: c_int) -> &'static str {
    match code {
        0 => "none",
        1 => "unknown",
        2 => "invalid argument",
        3 => "invalid operation",
        4 => "out of memory",
        5 => "unsupported hardware",
        6 => "cancelled",
        _ => "unrecognised error code",
    }
}

type NewDevice = unsafe extern "C" fn(device_type: c_int) -> DeviceHandle;
type DeviceVoid = unsafe extern "C" fn(device: DeviceHandle);
type GetDeviceError =
    unsafe extern "C" fn(device: DeviceHandle, out_message: *mut *const c_char) -> c_int;
type GetDeviceInt = unsafe extern "C" fn(device: DeviceHandle, name: *const c_char) -> c_int;
type NewFilter =
    unsafe extern "C" fn(device: DeviceHandle, filter_type: *const c_char) -> FilterHandle;
type SetSharedFilterImage = unsafe extern "C" fn(
    filter: FilterHandle,
    name: *const c_char,
    dev_ptr: *mut c_void,
    format: c_int,
    width: usize,
    height: usize,
    byte_offset: usize,
    pixel_byte_stride: usize,
    row_byte_stride: usize,
);
type SetFilterBool = unsafe extern "C" fn(filter: FilterHandle, name: *const c_char, value: bool);
type FilterVoid = unsafe extern "C" fn(filter: FilterHandle);

/// The resolved entry points, together with the library they point into.
///
/// The function pointers are plain copies taken out of `libloading` symbols; they stay valid
/// because `_library` is kept loaded for as long as this value lives.
pub(crate) struct Api {
    pub new_device: NewDevice,
    pub commit_device: DeviceVoid,
    pub release_device: DeviceVoid,
    pub get_device_error: GetDeviceError,
    pub get_device_int: GetDeviceInt,
    pub new_filter: NewFilter,
    pub set_shared_filter_image: SetSharedFilterImage,
    pub set_filter_bool: SetFilterBool,
    pub commit_filter: FilterVoid,
    pub execute_filter: FilterVoid,
    pub release_filter: FilterVoid,
    _library: Library,
}

impl Api {
    /// Resolves every entry point in `library`, or names the first one that is missing.
    ///
    /// # Safety
    /// `library` must be an OIDN 2.x library, so that each symbol has the C signature given
    /// to it here.
    pub(crate) unsafe fn resolve(library: Library) -> Result<Api, String> {
        /// Copies the function pointer named `name` (NUL-terminated) out of `library`.
        unsafe fn get<T: Copy>(library: &Library, name: &[u8]) -> Result<T, String> {
            // SAFETY: the caller promises `T` is the symbol's C signature.
            match unsafe { library.get::<T>(name) } {
                Ok(symbol) => Ok(*symbol),
                Err(error) => Err(format!(
                    "missing entry point {}: {error}",
                    String::from_utf8_lossy(&name[..name.len() - 1])
                )),
            }
        }
        // SAFETY (every call below): the signatures are those of oidn.h for OIDN 2.x, which
        // the caller vouches for.
        unsafe {
            Ok(Api {
                new_device: get(&library, b"oidnNewDevice\0")?,
                commit_device: get(&library, b"oidnCommitDevice\0")?,
                release_device: get(&library, b"oidnReleaseDevice\0")?,
                get_device_error: get(&library, b"oidnGetDeviceError\0")?,
                get_device_int: get(&library, b"oidnGetDeviceInt\0")?,
                new_filter: get(&library, b"oidnNewFilter\0")?,
                set_shared_filter_image: get(&library, b"oidnSetSharedFilterImage\0")?,
                set_filter_bool: get(&library, b"oidnSetFilterBool\0")?,
                commit_filter: get(&library, b"oidnCommitFilter\0")?,
                execute_filter: get(&library, b"oidnExecuteFilter\0")?,
                release_filter: get(&library, b"oidnReleaseFilter\0")?,
                _library: library,
            })
        }
    }
}
