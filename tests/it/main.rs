//! One integration-test binary; modules mirror the source tree.

mod alloc;
mod axis;
mod bench;
mod bus;

mod cmd_render;
mod cmd_sim;
mod compare;
mod design_matrix;
mod design_reads;
mod ecp5;
mod errors;
mod explore;
mod family;
mod fast;
mod fit;
mod flag_and_path_errors;
mod grid;
mod hdl;
mod helpers;
mod hexfile;
mod host_docs;
mod init_files;
mod lanes;
mod layout;
mod limits;
mod manual;
mod map_fit;
mod map_flags;
mod map_stream;
mod model_stages;
mod mult_proof;
mod nothing_left;
mod output_safety;
mod prefix;
mod progress;
mod prove;
mod readme;
mod render;
mod rtl_generate;
mod rtl_in_loop;
mod rtl_ip;
mod sim;
mod slurm_client;
mod stability;
mod stdout;
mod stress;
mod symmetry;
mod vectors;
mod volume;

/// Counts every allocation of the test binary per thread (tests/it/alloc.rs), so tests can
/// bound the memory a call takes.
#[global_allocator]
static ALLOC: alloc::Counting = alloc::Counting;
