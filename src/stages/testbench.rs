//! What a testbench template reads ([`TbData`]): built by `emit::tb` from a stage's ports,
//! fields and latency, rendered by the stage's own `<name>_tb.v` (which extends
//! `templates/tb/base_tb.v`).

/// A signal of the testbench: a design port.
pub struct Sig {
    pub name: &'static str,
    /// `[n-1:0]`, or blanks for one bit, padded so the names line up.
    pub range: String,
    pub init: String,
    /// The instance connection, `.name (name)`, names padded.
    pub pin: String,
}

/// A vector field as the testbench stores and drives or checks it.
pub struct FieldView {
    pub name: &'static str,
    pub bits: u32,
    /// Always a range, `[0:0]` for one bit, so every ring is declared alike.
    pub range: String,
    /// The design port the field drives or is compared with; empty for `map` of the top,
    /// which steers the testbench itself.
    pub port: String,
}

/// A file the testbench reads or passes to the design: its parameter and default path.
pub struct TbFile {
    pub param: String,
    pub default: String,
}

/// Everything the testbench templates read.
pub struct TbData {
    /// The configuration: a testbench that maps the vector fields onto ports of its own
    /// ([`crate::stages::Vectors::inner`]) reads their layout from it.
    pub cfg: crate::config::Config,
    pub header: String,
    /// The module under test ([`crate::stages::Unit::module`]); the testbench is `<module>_tb`.
    pub module: String,
    /// `tb/<module>_tb.v`.
    pub tb_file: String,
    pub summary: String,
    pub vector_file: String,
    pub field_list: String,
    pub latency: u32,
    pub depth: u32,
    pub depth_bits: u32,
    /// Samples a clock ([`crate::stages::Vectors::lanes`]): 1, or the lanes of rmap_lanes.
    pub lanes: u32,
    /// The ring of vectors read but not yet checked, with lanes: `lanes` per beat of the
    /// `depth` ring (a power of two), and its log2.
    pub vdepth: u32,
    pub vdepth_bits: u32,
    pub full_speed: u32,
    pub reset_at: u32,
    pub timeout: u32,
    pub seed: u32,
    pub has_en: bool,
    /// The top with valid/ready flow control: ready_i random, acceptance by ready_o.
    pub handshake: bool,
    /// `{zero_o, i_o, ...}`: every checked output, and its width (the hold check).
    pub outs_concat: String,
    pub outs_bits: u32,
    pub inputs: Vec<Sig>,
    pub outputs: Vec<Sig>,
    pub ports: Vec<Sig>,
    pub fields: Vec<FieldView>,
    /// Input fields with a port.
    pub in_fields: Vec<FieldView>,
    pub out_fields: Vec<FieldView>,
    pub scan_format: String,
    pub scan_args: String,
    pub in_format: String,
    pub in_args: String,
    pub out_format: String,
    pub exp_args: String,
    pub got_args: String,
    /// Files the design reads with `$readmemh` and the testbench itself (`map2_*`): one string
    /// parameter of the testbench each, so a run from another directory sets their paths.
    pub files: Vec<TbFile>,
    /// ` #(...)` passing the design's init-file parameters to the instance under test.
    pub dut_params: String,
    /// The declarations and instance of the reciprocal ROM the design reads through its
    /// `recip_*` ports when rmap_lanes shares it (empty otherwise).
    pub rom: String,
    /// The second map's files, loaded through the host port (map_lookup, atan_rom with
    /// `comp_table = ram`, and the top): one per axis, and the table with `comp_table = ram`.
    pub map2_params: Vec<Map2File>,
    /// `map2_*.hex` with the prefix, for messages.
    pub map2_pattern: String,
    pub map_entries: u32,
    pub map_addr_bits: u32,
    pub map_bits: u32,
    pub nwrites: u32,
    /// Entries of the compensation table the host port writes after the maps (0 without).
    pub table_entries: u32,
}

/// One file of the second map in a testbench: its parameter, and the first and last index of
/// the testbench's write list it fills (Verilog expressions of MAP_ENTRIES, TABLE_ENTRIES).
#[derive(Clone, Debug)]
pub struct Map2File {
    pub param: String,
    pub first: String,
    pub last: String,
}
