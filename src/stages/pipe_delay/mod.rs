//! The sideband delay line: q_o is d_i of DEPTH enabled clocks ago. The top instantiates one
//! per sideband signal (axis and signs, read buffer, zero flag, colour), each DEPTH from its
//! own `SidebandDelays` (in `stages::rmap_top`).

use super::unit::{Head, Unit};
use crate::config::Config;
use crate::hdl::ports::{i, Dir, Port, Width};
use askama::Template;

pub struct PipeDelay;

#[derive(Template)]
#[template(path = "pipe_delay/pipe_delay.v", syntax = "verilog")]
struct Verilog {
    h: Head,
}

impl Unit for PipeDelay {
    fn name(&self) -> &'static str {
        "pipe_delay"
    }

    fn ports(&self, _cfg: &Config) -> Vec<Port> {
        vec![
            i("clk_i", 1, ""),
            i("en_i", 1, "low holds the line"),
            Port {
                name: "d_i",
                dir: Dir::Input,
                width: Width::Param("WIDTH"),
                note: "",
            },
            Port {
                name: "q_o",
                dir: Dir::Output,
                width: Width::Param("WIDTH"),
                note: "d_i of DEPTH enabled clocks ago",
            },
        ]
    }

    /// Its DEPTH parameter.
    fn latency(&self, _cfg: &Config) -> Option<u32> {
        None
    }

    fn render(&self, _cfg: &Config, h: Head) -> askama::Result<String> {
        Verilog { h }.render()
    }
}
