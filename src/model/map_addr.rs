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
        let i = cfg.index_bits;
        (self.s_max << (2 * i + 2))
            | (self.s_u << (2 * i + 1))
            | (self.i_u << (i + 1))
            | (self.s_v << i)
            | self.i_v
    }

    /// Splits an address into its fields (the inverse of [`MapAddr::encode`]).
    pub fn decode(cfg: &Config, addr: u32) -> MapAddr {
        let i = cfg.index_bits;
        let idx = cfg.entries() - 1;
        MapAddr {
            s_max: (addr >> (2 * i + 2)) & 1,
            s_u: (addr >> (2 * i + 1)) & 1,
            i_u: (addr >> (i + 1)) & idx,
            s_v: (addr >> i) & 1,
            i_v: addr & idx,
        }
    }
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
