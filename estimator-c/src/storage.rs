//! Caller-provided storage, handles, and the pointer reads and writes of the boundary: the
//! only `unsafe` code of the crate.

use crate::error::est_error;
use core::ffi::c_void;
use core::mem::{align_of, size_of};
use estimator_core::nalgebra::Vector3;

/// The version of this interface, `major << 16 | minor << 8 | patch`: a program checks at
/// start-up that the library it links (`est_api_version()`) has the major version of the
/// header it was compiled with.
pub const EST_API_VERSION: u32 = 0x0001_0000;

/// The library's `EST_API_VERSION`.
#[no_mangle]
pub extern "C" fn est_api_version() -> u32 {
    EST_API_VERSION
}

/// Marks storage holding an attitude navigator; written last by its init. A word of one
/// repeated byte, so that the check of every call is one compare with an immediate on a
/// Cortex-M (Thumb-2 encodes `0xXYXYXYXY`), not a constant loaded first.
pub(crate) const MAGIC_ATTITUDE: u32 = 0x6161_6161;
/// Marks storage holding an INS navigator (as [`MAGIC_ATTITUDE`]).
pub(crate) const MAGIC_INS: u32 = 0x6969_6969;

/// What a navigator's storage holds: the magic word at its start, then the navigator.
#[repr(C)]
pub(crate) struct Slot<N> {
    pub(crate) magic: u32,
    pub(crate) nav: N,
}

pub(crate) const fn slot_size<N>() -> usize {
    size_of::<Slot<N>>()
}

pub(crate) const fn slot_align<N>() -> usize {
    align_of::<Slot<N>>()
}

/// Builds `nav` in `storage` (null, alignment and size checked) and returns the handle: the
/// start of the storage, with `magic` written.
///
/// # Safety
/// `storage` is null or points to `size` writable bytes.
pub(crate) unsafe fn init_slot<N, H>(
    storage: *mut c_void,
    size: usize,
    magic: u32,
    make: impl FnOnce() -> Result<N, est_error>,
) -> Result<*mut H, est_error> {
    let slot = storage.cast::<Slot<N>>();
    if slot.is_null() {
        return Err(est_error::EST_ERR_NULL_POINTER);
    }
    if !slot.is_aligned() {
        return Err(est_error::EST_ERR_MISALIGNED);
    }
    if size < slot_size::<N>() {
        return Err(est_error::EST_ERR_STORAGE_TOO_SMALL);
    }
    let nav = make()?;
    // SAFETY: `slot` is non-null and aligned for `Slot<N>` (checked above), and the caller
    // gives `size` writable bytes at it (the # Safety section of `est_*_init`), at least
    // `size_of::<Slot<N>>()` (checked above). `write` does not read or drop what was there.
    unsafe { slot.write(Slot { magic, nav }) };
    Ok(slot.cast::<H>())
}

/// The body of every `est_*_init`: `out` checked before anything is built, the configuration
/// `cfg` read and turned into a navigator by `build`, built in `storage` with `magic`, and the
/// handle written to `*out`.
///
/// # Safety
/// As `est_*_init`: `storage` is null or points to `size` writable bytes; `cfg` is null or
/// points to an initialized `C`; `out` is null or points to a writable `*mut H`.
pub(crate) unsafe fn init_nav<C: Copy, N, H>(
    storage: *mut c_void,
    size: usize,
    cfg: *const C,
    out: *mut *mut H,
    magic: u32,
    build: impl FnOnce(C) -> Result<N, est_error>,
) -> est_error {
    let built = check_out(out).and_then(|()| {
        // SAFETY: the # Safety section covers `cfg`.
        let config = unsafe { read_in(cfg) }?;
        // SAFETY: the # Safety section covers `storage` and `size`.
        unsafe { init_slot::<N, H>(storage, size, magic, || build(config)) }
    });
    // SAFETY: the # Safety section covers `out` (checked before anything was built).
    crate::error::code(built.and_then(|handle| unsafe { write_out(out, handle) }))
}

/// Checks a handle (non-null, aligned, its magic word set by the init of the same kind).
///
/// # Safety
/// `handle` is null or points to at least 4 initialized bytes.
unsafe fn checked_slot<N, H>(handle: *const H, magic: u32) -> Result<*const Slot<N>, est_error> {
    let slot = handle.cast::<Slot<N>>();
    if slot.is_null() {
        return Err(est_error::EST_ERR_NULL_POINTER);
    }
    if !slot.is_aligned() {
        return Err(est_error::EST_ERR_MISALIGNED);
    }
    // SAFETY: `slot` is non-null and aligned for `Slot<N>`, hence for its first field, a
    // `u32` at offset 0 (`repr(C)`); a handle points to storage of `est_*_storage_size()`
    // initialized bytes (as documented: the storage given to init, or any other
    // initialized memory the caller mistakes for one), so these 4 bytes are readable.
    let found = unsafe { core::ptr::addr_of!((*slot).magic).read() };
    if found == magic {
        Ok(slot)
    } else {
        Err(est_error::EST_ERR_NOT_INITIALIZED)
    }
}

/// The navigator behind a handle, shared.
///
/// # Safety
/// `handle` is null or points to initialized memory of `size_of::<Slot<N>>()` bytes, and
/// nothing writes it while the reference lives.
pub(crate) unsafe fn nav_ref<'a, N, H>(handle: *const H, magic: u32) -> Result<&'a N, est_error> {
    // SAFETY: the # Safety section covers the 4 bytes of the magic word.
    let slot = unsafe { checked_slot::<N, H>(handle, magic) }?;
    // SAFETY: the magic word is written by `init_slot` only, in the same write as a valid
    // `N` (the magic of each navigator kind differs, so `N` is the type that was written);
    // the caller does not use the handle from elsewhere during the call (documented).
    Ok(unsafe { &(*slot).nav })
}

/// The navigator behind a handle, exclusive.
///
/// # Safety
/// As [`nav_ref`], and nothing else reads or writes it while the reference lives.
pub(crate) unsafe fn nav_mut<'a, N, H>(handle: *mut H, magic: u32) -> Result<&'a mut N, est_error> {
    // SAFETY: the # Safety section covers the 4 bytes of the magic word.
    let slot = unsafe { checked_slot::<N, H>(handle, magic) }?.cast_mut();
    // SAFETY: as in `nav_ref`; the handle is the caller's `*mut`, derived from the writable
    // storage given to init, and no other reference to it exists during the call.
    Ok(unsafe { &mut (*slot).nav })
}

/// Reads a configuration or other input struct.
///
/// # Safety
/// `p` is null or points to an initialized `T` (for a `T` with `bool` fields: each 0 or 1).
pub(crate) unsafe fn read_in<T: Copy>(p: *const T) -> Result<T, est_error> {
    if p.is_null() {
        return Err(est_error::EST_ERR_NULL_POINTER);
    }
    if !p.is_aligned() {
        return Err(est_error::EST_ERR_MISALIGNED);
    }
    // SAFETY: non-null and aligned (checked); the caller gives a pointer to a `T` it
    // initialized (as documented). Every `T` read here is a `repr(C)` struct of
    // floats, integers and `bool`s (a C `bool` holds only 0 or 1) or an array of floats, so
    // any initialized C value of it is a valid Rust value.
    Ok(unsafe { p.read() })
}

/// Reads a `float[3]`.
///
/// # Safety
/// `p` is null or points to 3 initialized floats.
pub(crate) unsafe fn read_vec3(p: *const f32) -> Result<Vector3<f32>, est_error> {
    // SAFETY: as required above: 3 floats, which is one `[f32; 3]` (alignment checked).
    let [x, y, z] = unsafe { read_in(p.cast::<[f32; 3]>()) }?;
    Ok(Vector3::new(x, y, z))
}

/// Reads two `float[3]` (an IMU sample's gyro and accelerometer): the null and alignment
/// checks of both in one branch each.
///
/// # Safety
/// `a` and `b` are null or point to 3 initialized floats each.
pub(crate) unsafe fn read_vec3_pair(
    a: *const f32,
    b: *const f32,
) -> Result<(Vector3<f32>, Vector3<f32>), est_error> {
    if a.is_null() || b.is_null() {
        return Err(est_error::EST_ERR_NULL_POINTER);
    }
    if !(a.addr() | b.addr()).is_multiple_of(align_of::<f32>()) {
        return Err(est_error::EST_ERR_MISALIGNED);
    }
    // SAFETY: non-null and aligned (checked); the caller gives 3 initialized floats at each
    // (as documented), which is one `[f32; 3]`.
    let ([ax, ay, az], [bx, by, bz]) =
        unsafe { (a.cast::<[f32; 3]>().read(), b.cast::<[f32; 3]>().read()) };
    Ok((Vector3::new(ax, ay, az), Vector3::new(bx, by, bz)))
}

/// Writes an output struct.
///
/// # Safety
/// `p` is null or points to writable memory for one `T`.
pub(crate) unsafe fn write_out<T>(p: *mut T, value: T) -> Result<(), est_error> {
    if p.is_null() {
        return Err(est_error::EST_ERR_NULL_POINTER);
    }
    if !p.is_aligned() {
        return Err(est_error::EST_ERR_MISALIGNED);
    }
    // SAFETY: non-null and aligned (checked); the caller gives a pointer to writable memory
    // for one `T` (as documented). `T` is a plain `repr(C)` struct without drop
    // glue, so not reading or dropping the old contents is correct.
    unsafe { p.write(value) };
    Ok(())
}

/// Checks that an output pointer can be written, before a call that changes the navigator:
/// an error for it must leave the navigator unchanged.
pub(crate) fn check_out<T>(p: *mut T) -> Result<(), est_error> {
    if p.is_null() {
        Err(est_error::EST_ERR_NULL_POINTER)
    } else if !p.is_aligned() {
        Err(est_error::EST_ERR_MISALIGNED)
    } else {
        Ok(())
    }
}

/// A vector as `float[3]`.
pub(crate) fn vec3(v: &Vector3<f32>) -> [f32; 3] {
    [v.x, v.y, v.z]
}
