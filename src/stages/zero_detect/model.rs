//! Zero detect: a gradient whose three components are all zero has no direction. The
//! pipeline flags it at the output and forces the intensity (and colour) to zero, so the
//! host decides what such a sample shows.

#[inline]
pub fn eval(g: [i32; 3]) -> bool {
    g == [0, 0, 0]
}
