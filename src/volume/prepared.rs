//! A volume prepared for casting ([`Prepared`]): its quantised gradients and bricks,
//! computed once per gradient width and brick size. Separate from the caster because one
//! prepared volume serves every view, transfer function and shader.

use super::bricks::Bricks;
use super::gradient::Gradients;
use super::Volume;

/// A volume prepared for one gradient width and brick size: what does not change with the
/// view, the transfer function or the shading.
pub struct Prepared<'a> {
    pub vol: &'a Volume,
    pub grads: Gradients,
    pub bricks: Bricks,
}

impl<'a> Prepared<'a> {
    pub fn new(vol: &'a Volume, grad_bits: u32, brick: usize) -> Prepared<'a> {
        let grads = super::gradient::gradients(vol, grad_bits);
        let bricks = Bricks::new(vol, brick, &grads.data);
        Prepared { vol, grads, bricks }
    }

    /// [`Prepared::new`], refusing with an error a volume whose gradients the machine has no
    /// memory for.
    pub fn try_new(vol: &'a Volume, grad_bits: u32, brick: usize) -> anyhow::Result<Prepared<'a>> {
        let grads = super::gradient::try_gradients(vol, grad_bits)?;
        let bricks = Bricks::new(vol, brick, &grads.data);
        Ok(Prepared { vol, grads, bricks })
    }
}
