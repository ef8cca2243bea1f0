//! One integration-test binary; modules mirror the source tree.

mod cmd_render;
mod fast;
mod helpers;
mod hexfile;
mod model_stages;
mod render;
mod rtl_generate;
mod sim;
mod symmetry;
mod vectors;
