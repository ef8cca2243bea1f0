//! One integration-test binary; modules mirror the source tree.

mod helpers;
mod hexfile;
mod model_stages;
