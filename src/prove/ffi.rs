//! The Verilated models of `rmapgen prove`, loaded into this process as shared objects
//! (`dlopen`), so that rmapgen hands a harness millions of inputs at a time and compares its
//! outputs with the model in memory: no text files or pipes in between, which at 2^36 inputs
//! would cost more than the simulation. The harnesses (tb/prove_front.cpp, tb/prove_top.cpp)
//! only apply inputs and return outputs; every decision is made here, in Rust.

use anyhow::{bail, Result};
use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::Path;

// glibc (2.34 and later) has dlopen in libc itself, which every Rust program links.
extern "C" {
    fn dlopen(filename: *const c_char, flag: c_int) -> *mut c_void;
    fn dlsym(handle: *mut c_void, symbol: *const c_char) -> *mut c_void;
    fn dlerror() -> *mut c_char;
}
const RTLD_NOW: c_int = 2;

fn last_error() -> String {
    // SAFETY: dlerror returns null or a NUL-terminated string owned by libc.
    unsafe {
        let e = dlerror();
        if e.is_null() {
            "unknown error".into()
        } else {
            CStr::from_ptr(e).to_string_lossy().into_owned()
        }
    }
}

/// A loaded shared object. It is never unloaded: a run loads two.
pub struct Library {
    handle: *mut c_void,
}

impl Library {
    pub fn open(path: &Path) -> Result<Library> {
        let c = CString::new(path.as_os_str().as_encoded_bytes())?;
        // SAFETY: a valid C string; RTLD_NOW resolves every symbol now, so a broken build
        // fails here rather than at a call.
        let handle = unsafe { dlopen(c.as_ptr(), RTLD_NOW) };
        if handle.is_null() {
            bail!("cannot load {}: {}", path.display(), last_error());
        }
        Ok(Library { handle })
    }

    /// The address of the function `name`.
    fn symbol(&self, name: &str) -> Result<*mut c_void> {
        let c = CString::new(name)?;
        // SAFETY: a handle from dlopen and a valid C string.
        let p = unsafe { dlsym(self.handle, c.as_ptr()) };
        if p.is_null() {
            bail!("the harness has no {name}: {}", last_error());
        }
        Ok(p)
    }
}

type New = unsafe extern "C" fn() -> *mut c_void;
type Lanes = unsafe extern "C" fn() -> usize;
type Free = unsafe extern "C" fn(*mut c_void);
type FrontRun = unsafe extern "C" fn(*mut c_void, *const u16, usize, *mut u8, *mut u64) -> c_int;
type TopRun = unsafe extern "C" fn(*mut c_void, *const u32, usize, *mut u32) -> std::ffi::c_long;
type TopWrite = unsafe extern "C" fn(*mut c_void, *const u32, usize) -> usize;
type TopSwap = unsafe extern "C" fn(*mut c_void);

/// The Verilated front (tb/prove_front.cpp): zero detect and sort & shift side by side.
pub struct Front {
    model: *mut c_void,
    run: FrontRun,
    free: Free,
    /// [`Front::run`] takes a multiple of this many gradients.
    pub lanes: usize,
}

impl Front {
    pub fn new(lib: &Library) -> Result<Front> {
        // SAFETY: the symbols have the signatures tb/prove_front.cpp gives them.
        unsafe {
            let new: New = std::mem::transmute::<*mut c_void, New>(lib.symbol("rp_front_new")?);
            let run = std::mem::transmute::<*mut c_void, FrontRun>(lib.symbol("rp_front_run")?);
            let free = std::mem::transmute::<*mut c_void, Free>(lib.symbol("rp_front_free")?);
            let lanes = std::mem::transmute::<*mut c_void, Lanes>(lib.symbol("rp_front_lanes")?)();
            Ok(Front {
                model: new(),
                run,
                free,
                lanes,
            })
        }
    }

    /// Applies `g` (gx, gy, gz per sample; a multiple of [`Front::lanes`] samples),
    /// `lanes` per clock; `zero` and `ss` receive each module's outputs in order.
    pub fn run(&mut self, g: &[u16], zero: &mut [u8], ss: &mut [u64]) -> Result<()> {
        let n = g.len() / 3;
        assert!(
            zero.len() >= n && ss.len() >= n && g.len() == 3 * n && n.is_multiple_of(self.lanes)
        );
        // SAFETY: the buffers hold n samples each, as rp_front_run reads and writes.
        let r = unsafe {
            (self.run)(
                self.model,
                g.as_ptr(),
                n,
                zero.as_mut_ptr(),
                ss.as_mut_ptr(),
            )
        };
        if r != 0 {
            bail!("the Verilated front delivered more or fewer than {n} results");
        }
        Ok(())
    }
}

impl Drop for Front {
    fn drop(&mut self) {
        // SAFETY: a model from rp_front_new, freed once.
        unsafe { (self.free)(self.model) }
    }
}

/// The Verilated top (tb/prove_top.cpp).
pub struct Top {
    model: *mut c_void,
    run: TopRun,
    write: TopWrite,
    swap: TopSwap,
    free: Free,
}

/// Fields per sample of [`Top::run`]'s input (gx gy gz r g b) and output (zero i r g b).
pub const TOP_IN: usize = 6;
pub const TOP_OUT: usize = 5;

impl Top {
    pub fn new(lib: &Library) -> Result<Top> {
        // SAFETY: the symbols have the signatures tb/prove_top.cpp gives them.
        unsafe {
            let new: New = std::mem::transmute::<*mut c_void, New>(lib.symbol("rp_top_new")?);
            let run = std::mem::transmute::<*mut c_void, TopRun>(lib.symbol("rp_top_run")?);
            let write = std::mem::transmute::<*mut c_void, TopWrite>(lib.symbol("rp_top_write")?);
            let swap = std::mem::transmute::<*mut c_void, TopSwap>(lib.symbol("rp_top_swap")?);
            let free = std::mem::transmute::<*mut c_void, Free>(lib.symbol("rp_top_free")?);
            Ok(Top {
                model: new(),
                run,
                write,
                swap,
                free,
            })
        }
    }

    /// Applies `input` ([`TOP_IN`] fields per sample) one per clock; `out` receives
    /// [`TOP_OUT`] fields per result, in order. Returns the number of results the
    /// simulation delivered, or `None` if the design lost or added a sample (a result that
    /// never left the pipeline, or one more than was driven): a wrong design, which the
    /// caller reports as a failure of its part.
    pub fn run(&mut self, input: &[u32], out: &mut [u32]) -> Option<u64> {
        let n = input.len() / TOP_IN;
        assert!(input.len() == TOP_IN * n && out.len() >= TOP_OUT * n);
        // SAFETY: the buffers hold n samples each, as rp_top_run reads and writes.
        let r = unsafe { (self.run)(self.model, input.as_ptr(), n, out.as_mut_ptr()) };
        (r >= 0 && r as usize == n).then_some(r as u64)
    }

    /// Host writes into the back map buffer, one per clock.
    pub fn write(&mut self, writes: &[crate::map_stream::Write]) -> Result<()> {
        let flat: Vec<u32> = writes
            .iter()
            .flat_map(|w| [w.axis, w.addr, w.data])
            .collect();
        // SAFETY: flat holds 3 words per write, as rp_top_write reads.
        let n = unsafe { (self.write)(self.model, flat.as_ptr(), writes.len()) };
        if n != writes.len() {
            bail!("the Verilated top took {n} of {} host writes", writes.len());
        }
        Ok(())
    }

    /// Exchanges the front and back map buffers (the pipeline is empty between runs).
    pub fn swap(&mut self) {
        // SAFETY: a model from rp_top_new.
        unsafe { (self.swap)(self.model) }
    }
}

impl Drop for Top {
    fn drop(&mut self) {
        // SAFETY: a model from rp_top_new, freed once.
        unsafe { (self.free)(self.model) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A library that cannot be loaded is refused with the loader's own reason; a symbol the
    /// library lacks, with its name and the loader's reason.
    #[test]
    fn load_failures_say_why() {
        let e = Library::open(Path::new("/nonexistent/libnothing.so"))
            .err()
            .expect("no such library")
            .to_string();
        assert!(
            e.starts_with("cannot load /nonexistent/libnothing.so: ")
                && e.contains("No such file or directory"),
            "{e}"
        );
        // A file the test makes in a directory of its own, removed with the directory.
        let tmp = tempfile::tempdir().unwrap();
        let not_elf = tmp.path().join("libnot-elf.so");
        std::fs::write(&not_elf, "not a shared object").unwrap();
        let e = Library::open(&not_elf)
            .err()
            .expect("not a library")
            .to_string();
        assert!(
            e.contains("invalid ELF header") || e.contains("too short"),
            "{e}"
        );
        // libc is in every process, so loading it succeeds; it has no such symbol.
        let libc = Library::open(Path::new("libc.so.6")).expect("libc loads");
        let e = libc
            .symbol("rmapgen_no_such_symbol")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("the harness has no rmapgen_no_such_symbol: ")
                && e.contains("undefined symbol"),
            "{e}"
        );
    }
}
