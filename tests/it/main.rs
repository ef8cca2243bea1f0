//! One integration-test binary; modules mirror the source tree.

mod helpers;
