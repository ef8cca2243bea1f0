//! rmapgen: a generator of synthesizable Verilog for the on-chip reflectance-map shader of
//! Terwisscha van Scheltinga, Smit and Bosma, with the bit-accurate model that checks it.

pub mod bench;
pub mod cancel;
pub mod cmd;
pub mod config;
pub mod design;
pub mod design_dir;
pub mod disk;
pub mod emit;
pub mod explore;
pub mod family;
pub mod fit;
pub mod flow;
pub mod geometry;
pub mod grid;
pub mod hdl;
pub mod hexfile;
pub mod map_stream;
pub mod model;
pub mod mutants;
pub mod output;
pub mod plotting;
pub mod prove;
pub mod reference;
pub mod render;
pub mod rng;
pub mod scene;
pub mod sim;
pub mod stages;
pub mod stress;
pub mod toml_input;
pub mod toolchain;
pub mod vectors;
pub mod volume;
