//! The sign patterns of a magnitude triple in an exhaustive run: which are valid, and the
//! signed gradient each stands for. Separate because both the input pass and the error
//! search enumerate gradients through them.

/// Valid sign codes (x | y << 1 | z << 2) of a magnitude triple: a zero component is never
/// negative and a component of 2^(G-1) always is.
pub(super) fn sign_codes(mags: [u32; 3], full: u32) -> impl Iterator<Item = u32> {
    (0..8u32).filter(move |code| {
        (0..3).all(|k| {
            let neg = (code >> k) & 1 == 1;
            // Zero is never negative; 2^(G-1) is always negative.
            (mags[k] != 0 || !neg) && (mags[k] != full || neg)
        })
    })
}

pub(super) fn signed(mags: [u32; 3], code: u32) -> [i32; 3] {
    [0, 1, 2].map(|k| {
        if (code >> k) & 1 == 1 {
            -(mags[k] as i32)
        } else {
            mags[k] as i32
        }
    })
}

/// A gradient with these magnitudes, positive where the range allows: where an angle was
/// found (signs do not change it).
pub(super) fn representative(mags: [u32; 3], full: u32) -> [i32; 3] {
    signed(
        mags,
        sign_codes(mags, full)
            .next()
            .expect("some sign code is valid"),
    )
}
