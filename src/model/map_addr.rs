//! The address layout of a per-axis map, defined once: `{s_max, s_u, i_u, s_v, i_v}`, signs
//! one bit each and indices `index_bits` each (`3 + 2 * index_bits` bits). The map builders
//! write entries at these addresses, the look-up stage reads them, and the RTL's banks
//! (`stages::map_bank::banks`) split the same fields across their four memories.

use crate::config::Config;

/// Fields of a map address: the signs of the max, u and v components and the entry indices
/// along u and v.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MapAddr {
    pub s_max: u32,
    pub s_u: u32,
    pub i_u: u32,
    pub s_v: u32,
    pub i_v: u32,
}

impl MapAddr {
    /// The address of these fields in the map of one axis.
    #[inline]
    pub fn encode(self, cfg: &Config) -> u32 {
        let [s_max, s_u, i_u, s_v, i_v] = fields(cfg);
        (self.s_max << s_max.lsb)
            | (self.s_u << s_u.lsb)
            | (self.i_u << i_u.lsb)
            | (self.s_v << s_v.lsb)
            | (self.i_v << i_v.lsb)
    }

    /// Splits an address into its fields (the inverse of [`MapAddr::encode`]).
    pub fn decode(cfg: &Config, addr: u32) -> MapAddr {
        let get = |f: Field| (addr >> f.lsb) & ((1 << f.width) - 1);
        let [s_max, s_u, i_u, s_v, i_v] = fields(cfg);
        MapAddr {
            s_max: get(s_max),
            s_u: get(s_u),
            i_u: get(i_u),
            s_v: get(s_v),
            i_v: get(i_v),
        }
    }
}

/// One field of the address layout: its name, lowest bit and width.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub lsb: u32,
    pub width: u32,
}

/// The layout's fields, most significant first: the one definition that [`MapAddr::encode`],
/// [`MapAddr::decode`] and the generated README's address table read.
#[inline]
pub fn fields(cfg: &Config) -> [Field; 5] {
    let i = cfg.index_bits;
    let f = |name, lsb, width| Field { name, lsb, width };
    [
        f("s_max", 2 * i + 2, 1),
        f("s_u", 2 * i + 1, 1),
        f("i_u", i + 1, i),
        f("s_v", i, 1),
        f("i_v", 0, i),
    ]
}

/// Address of entry (i_u, i_v) with these signs in the map of one axis.
#[inline]
pub fn addr(cfg: &Config, s_max: u32, s_u: u32, i_u: u32, s_v: u32, i_v: u32) -> u32 {
    MapAddr {
        s_max,
        s_u,
        i_u,
        s_v,
        i_v,
    }
    .encode(cfg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_inverts_encode_for_every_address() {
        for index_bits in 2..=6 {
            let cfg = Config {
                index_bits,
                ..Config::default()
            };
            for a in 0..cfg.map_entries() {
                assert_eq!(
                    MapAddr::decode(&cfg, a).encode(&cfg),
                    a,
                    "{}",
                    cfg.summary()
                );
            }
        }
    }

    #[test]
    fn fields_are_where_encode_puts_them() {
        for index_bits in 2..=6 {
            let cfg = Config {
                index_bits,
                ..Config::default()
            };
            let fs = fields(&cfg);
            assert_eq!(fs.iter().map(|f| f.width).sum::<u32>(), cfg.map_addr_bits());
            for (k, f) in fs.iter().enumerate() {
                let mut v = [0u32; 5];
                v[k] = (1 << f.width) - 1;
                assert_eq!(
                    addr(&cfg, v[0], v[1], v[2], v[3], v[4]),
                    v[k] << f.lsb,
                    "{f:?}"
                );
            }
        }
    }

    #[test]
    // The binary literals are grouped by field, not by nibble.
    #[allow(clippy::unusual_byte_groupings)]
    fn fields_sit_where_the_layout_says() {
        let cfg = Config::default(); // index_bits 3: {s_max, s_u, i_u[2:0], s_v, i_v[2:0]}
        assert_eq!(addr(&cfg, 1, 0, 0, 0, 0), 0b1_0_000_0_000);
        assert_eq!(addr(&cfg, 0, 1, 0, 0, 0), 0b0_1_000_0_000);
        assert_eq!(addr(&cfg, 0, 0, 5, 0, 0), 0b0_0_101_0_000);
        assert_eq!(addr(&cfg, 0, 0, 0, 1, 0), 0b0_0_000_1_000);
        assert_eq!(addr(&cfg, 0, 0, 0, 0, 6), 0b0_0_000_0_110);
    }
}
