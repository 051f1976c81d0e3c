//! SIGINT and SIGTERM during `migrate`, `bake` and `validate --fix`: a clean stop. The handler
//! only records the signal (in [`crate::asset::limits::STOP_SIGNAL`], where the long work below
//! the commands sees it too); the run looks at it between files and between a file's steps
//! (before each new texture is written, before a file's outputs are put in place), abandons the
//! files in progress, whose staged files are removed as they are dropped (see
//! [`super::staging`]), and keeps every output already put in place. The command then prints
//! one line saying what was finished and exits with 128 + the signal (130, 143).
//!
//! The handler is installed with SA_RESETHAND: a second Ctrl-C ends the process at once, as
//! if velvet had no handler (its staging files are then removed by the next run into that
//! folder). `validate --fix` installs it too (a file not yet written is abandoned, one
//! written stays); `validate` without it writes nothing and keeps the default behaviour.

use crate::asset::limits::STOP_SIGNAL as STOP;
use std::sync::atomic::Ordering;

/// The message of a file abandoned because the run was asked to stop.
pub const ABANDONED: &str = "stopped before it was finished (nothing of it was written)";

/// Installs the handler for SIGINT and SIGTERM (Unix; elsewhere nothing).
pub fn install() {
    #[cfg(unix)]
    {
        extern "C" fn on_signal(signal: libc::c_int) {
            // An atomic store is async-signal-safe.
            STOP.store(signal, Ordering::SeqCst);
        }
        for signal in [libc::SIGINT, libc::SIGTERM] {
            // SAFETY: sigaction with a zeroed struct, an empty mask and a handler that stores
            // to an atomic; SA_RESETHAND puts the default back once it has run, SA_RESTART
            // resumes the system calls it interrupted.
            unsafe {
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_signal as *const () as libc::sighandler_t;
                action.sa_flags = libc::SA_RESETHAND | libc::SA_RESTART;
                libc::sigemptyset(&mut action.sa_mask);
                libc::sigaction(signal, &action, std::ptr::null_mut());
            }
        }
    }
}

/// Ignores SIGXFSZ, for the whole process (Unix; elsewhere nothing). A write past a file-size
/// limit (`ulimit -f`, `prlimit --fsize`) would otherwise kill velvet mid-write, leaving its
/// temporary files behind; ignored, the write fails with EFBIG, which fails that file cleanly
/// (its staged files removed) as a full disk does.
pub fn ignore_file_size_signal() {
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to SIG_IGN has no handler to be unsafe in.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// The signal that asked the run to stop, if one has.
pub fn requested() -> Option<i32> {
    match STOP.load(Ordering::SeqCst) {
        0 => None,
        signal => Some(signal),
    }
}

/// `Err` with [`ABANDONED`] once the run was asked to stop: where a file's work checks it.
pub fn check() -> Result<(), String> {
    match requested() {
        None => Ok(()),
        Some(_) => Err(ABANDONED.to_string()),
    }
}

/// The signal's name, for the closing line.
pub fn name(signal: i32) -> String {
    #[cfg(unix)]
    {
        if signal == libc::SIGINT {
            return "SIGINT".to_string();
        }
        if signal == libc::SIGTERM {
            return "SIGTERM".to_string();
        }
    }
    format!("signal {signal}")
}
