//! The allocator a behavior's Lua state allocates through: every byte a script makes Lua
//! allocate is paid from its call's instruction budget ([`STEP_BYTES`] bytes an instruction),
//! and once a call has spent its budget a large allocation is refused.
//!
//! This meters what the instruction count cannot see: `..` copies its strings inside one VM
//! instruction, so `s = s .. s` or `s = s .. "x"` in a loop would do work without bound
//! between two budget checks. Charged by the bytes it allocates, such a loop spends its budget
//! in a few iterations, and its next large allocation fails: the call ends at once with a
//! budget overrun, not a thousand instructions later.
//!
//! The allocator wraps the one mlua installed (which keeps the memory limit and its counts);
//! it is taken out again before the runtime is dropped.

use super::{Meter, STEP_BYTES};
use mlua::{ffi, Lua};
use std::os::raw::c_void;
use std::ptr;
use std::sync::Arc;

/// The smallest allocation refused once a call has spent its budget. Smaller ones go on, so
/// that the overrun's own error and traceback can be made.
pub(crate) const REFUSED_WHEN_SPENT: usize = 64 << 10;

/// The allocator mlua installed and the meter the allocations are charged to: the user data
/// of [`charged`].
pub(crate) struct Charged {
    inner: ffi::lua_Alloc,
    inner_ud: *mut c_void,
    meter: Arc<Meter>,
}

/// Charges what Lua asks for, refuses it when a spent call asks for a lot, and hands the rest
/// to the allocator mlua installed.
unsafe extern "C" fn charged(
    ud: *mut c_void,
    block: *mut c_void,
    osize: usize,
    nsize: usize,
) -> *mut c_void {
    // SAFETY: `ud` is the `Charged` that `install` boxed; it is freed only after `uninstall`
    // has put the inner allocator back, so no allocation can reach it afterwards.
    let c = unsafe { &*(ud as *const Charged) };
    // For a new block (null `block`) `osize` is the kind of object, not a size.
    let grown = if block.is_null() { nsize } else { nsize.saturating_sub(osize) };
    if grown > 0 {
        if grown >= REFUSED_WHEN_SPENT && c.meter.refuses_growth() {
            // Lua keeps the old block and raises a memory error, which the meter reports as
            // the overrun it is.
            return ptr::null_mut();
        }
        c.meter.spend((grown / STEP_BYTES) as u64);
    }
    // SAFETY: the inner allocator with its own user data, and Lua's arguments unchanged.
    unsafe { (c.inner)(c.inner_ud, block, osize, nsize) }
}

/// The wrapper as installed in a state: freed by [`uninstall`].
pub(crate) struct Installed(ptr::NonNull<Charged>);

/// Puts [`charged`] in front of the state's allocator.
pub(crate) fn install(lua: &Lua, meter: Arc<Meter>) -> mlua::Result<Installed> {
    let boxed = Box::new(Charged { inner: charged, inner_ud: ptr::null_mut(), meter });
    let ud = Box::into_raw(boxed);
    // SAFETY: the closure runs on the state's own thread with no Lua code running; it reads
    // the current allocator and installs the wrapper around it in one go. `ud` is a live box.
    let done = unsafe {
        lua.exec_raw::<()>((), |state| {
            let mut inner_ud = ptr::null_mut();
            let inner = ffi::lua_getallocf(state, &mut inner_ud);
            (*ud).inner = inner;
            (*ud).inner_ud = inner_ud;
            ffi::lua_setallocf(state, charged, ud.cast());
        })
    };
    match done {
        // SAFETY: from `Box::into_raw`, never null.
        Ok(()) => Ok(Installed(unsafe { ptr::NonNull::new_unchecked(ud) })),
        Err(e) => {
            // SAFETY: not installed: nothing else holds the box.
            drop(unsafe { Box::from_raw(ud) });
            Err(e)
        }
    }
}

/// Puts the inner allocator back and frees the wrapper; if the state could not be reached
/// the wrapper is left allocated, since the state may still call through it.
pub(crate) fn uninstall(lua: &Lua, installed: Installed) {
    let ud = installed.0.as_ptr();
    // SAFETY: `ud` is live until freed below; blocks allocated through the wrapper came from
    // the inner allocator, which frees them from now on.
    let restored = unsafe {
        let (inner, inner_ud) = ((*ud).inner, (*ud).inner_ud);
        lua.exec_raw::<()>((), |state| ffi::lua_setallocf(state, inner, inner_ud))
    };
    if restored.is_ok() {
        // SAFETY: the state no longer knows the wrapper.
        drop(unsafe { Box::from_raw(ud) });
    }
}
