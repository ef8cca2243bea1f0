//! Verilog building blocks the stages use: ports as data and their rendering ([`ports`]), the
//! pipelined adder trees of the multipliers ([`adder_tree`]) and the same products inferred
//! ([`infer`]), and the trees' specification that the multiplier proof reads ([`tree_spec`]).
//! Below `stages`: nothing here knows a stage.

pub mod adder_tree;
pub mod infer;
pub mod ports;
pub mod tree_spec;

pub use ports::{Dir, Port, Width};
