//! One field of a vector line: its name, width and whether it drives the module or is checked
//! at its output. Each stage lists its own (`Vectors::fields`).

/// Whether a field drives the module or is checked at its output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dir {
    In,
    Out,
}

/// One field of a vector line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub bits: u32,
    pub dir: Dir,
}

impl Field {
    /// A field that drives the module.
    pub fn input(name: &'static str, bits: u32) -> Field {
        Field {
            name,
            bits,
            dir: Dir::In,
        }
    }

    /// A field checked at the module's output.
    pub fn output(name: &'static str, bits: u32) -> Field {
        Field {
            name,
            bits,
            dir: Dir::Out,
        }
    }
}
