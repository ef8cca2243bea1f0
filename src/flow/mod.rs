//! The FPGA flow: a design synthesised, placed and routed for a part ([`fpga`]), through the
//! tools of `crate::toolchain`.

pub mod fpga;
