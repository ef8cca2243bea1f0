//! The orthographic camera: parallel rays along minus the scene's view direction (the
//! direction from the surface towards the viewer, as the shading assumes), framing a box
//! (the ray caster gives it the volume's), whatever the transfer function shows of it.
//!
//! World coordinates: voxel (x, y, z) at (x sx, y sy, z sz). Image axes: `right` and `up`
//! with right x up = view (right-handed, like x, y, z for the default view along +z, which
//! gives the sphere render's orientation: x to the right, y up). `up` is the projection of
//! world +z, or of world +y when the view is within about 8 degrees of the z axis. Row 0 is
//! the top of the image. The square image spans the larger of the box's projected width and
//! height, plus 2%. Rays start on the plane through the box's centre moved back along the view
//! by half the box's diagonal plus one.

use anyhow::{bail, Result};
use glam::DVec3;

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub size: u32,
    /// Unit vector from the volume towards the viewer.
    pub view: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    /// World position of the image centre (the box's centre).
    pub centre: DVec3,
    /// World width of one pixel.
    pub pixel: f64,
    /// Distance from the centre back to where rays start (outside the box).
    pub distance: f64,
}

/// Checks an image-up direction against the view: finite, non-zero and not parallel to the
/// view (within about 0.06 degrees); returns it as a unit vector.
pub fn check_up(up: [f64; 3], view: DVec3) -> Result<DVec3> {
    let v = DVec3::from_array(up);
    if !v.is_finite() {
        bail!("--up {up:?} is not finite; give three finite numbers");
    }
    let Some(u) = crate::geometry::unit_direction(v) else {
        bail!("--up {up:?} has zero length; an up direction needs a non-zero component");
    };
    if u.cross(view).length() < 1e-3 {
        bail!(
            "--up {up:?} is parallel to the view direction {:?}; give an up direction across the view",
            view.to_array()
        );
    }
    Ok(u)
}

/// How the image frames the volume beyond the view direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    /// World direction shown as up in the image (projected across the view); `None` for
    /// world +z (+y when the view is within about 8 degrees of the z axis).
    pub up: Option<[f64; 3]>,
    /// Magnification about the box's centre: 2 shows the middle half of the default frame.
    pub zoom: f64,
    /// World direction of each voxel axis (rows; orthonormal): voxel (x, y, z) sits at
    /// `x sx axes[0] + y sy axes[1] + z sz axes[2]`. The camera works in the voxel-axis
    /// frame; its vectors are the world ones expressed there.
    pub axes: [[f64; 3]; 3],
}

impl Default for Framing {
    fn default() -> Self {
        Framing {
            up: None,
            zoom: 1.0,
            axes: IDENTITY,
        }
    }
}

/// Voxel axes along world x, y and z.
pub const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// A world vector in the voxel-axis frame (exact for [`IDENTITY`]).
pub fn to_axes(axes: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    axes.map(|a| a[0] * v[0] + a[1] * v[1] + a[2] * v[2])
}

impl Camera {
    /// A camera framing the box `lo..=hi` (in the voxel-axis frame of `framing.axes`),
    /// looking along `-view` (a world direction).
    pub fn new(
        lo: [f64; 3],
        hi: [f64; 3],
        view: [f64; 3],
        size: u32,
        framing: &Framing,
    ) -> Result<Camera> {
        let Some(view) = crate::geometry::unit_direction(DVec3::from_array(view)) else {
            bail!("view direction {view:?} must be a finite, non-zero vector");
        };
        if size == 0 {
            bail!("image size must be at least 1");
        }
        if !(framing.zoom.is_finite() && framing.zoom > 0.0) {
            bail!("--zoom {} must be a finite number > 0", framing.zoom);
        }
        let hint = match framing.up {
            Some(u) => check_up(u, view)?,
            None if view.z.abs() > 0.99 => DVec3::Y,
            None => DVec3::Z,
        };
        let right = hint.cross(view).normalize();
        let up = view.cross(right);
        let axes = |v: DVec3| DVec3::from_array(to_axes(&framing.axes, v.to_array()));
        let (view, right, up) = (axes(view), axes(right), axes(up));
        let (lo, hi) = (DVec3::from_array(lo), DVec3::from_array(hi));
        let extent = hi - lo;
        let centre = (lo + hi) * 0.5;
        let (mut hw, mut hh) = (0.0f64, 0.0f64);
        for i in 0..8 {
            let corner = DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            ) - centre;
            hw = hw.max(corner.dot(right).abs());
            hh = hh.max(corner.dot(up).abs());
        }
        let half = hw.max(hh).max(1e-9) * 1.02 / framing.zoom;
        Ok(Camera {
            size,
            view,
            right,
            up,
            centre,
            pixel: 2.0 * half / size as f64,
            distance: extent.length() * 0.5 + 1.0,
        })
    }

    /// The ray through the centre of pixel (x, y): its world start and unit direction.
    pub fn ray(&self, x: u32, y: u32) -> (DVec3, DVec3) {
        let h = self.size as f64 * 0.5;
        let u = (x as f64 + 0.5 - h) * self.pixel;
        let v = (h - (y as f64 + 0.5)) * self.pixel;
        (
            self.centre + u * self.right + v * self.up + self.distance * self.view,
            -self.view,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_view_matches_the_sphere_orientation() {
        let c = Camera::new(
            [0.0; 3],
            [10.0, 10.0, 4.0],
            [0.0, 0.0, 1.0],
            10,
            &Framing::default(),
        )
        .unwrap();
        assert_eq!((c.right, c.up), (DVec3::X, DVec3::Y));
        // The top-right pixel's ray starts at high x, high y, above the box, going down.
        let (o, d) = c.ray(9, 0);
        assert!(
            o.x > 9.0 && o.y > 9.0 && o.z > 4.0 && d == -DVec3::Z,
            "{o} {d}"
        );
        assert!((c.pixel - 10.0 * 1.02 / 10.0).abs() < 1e-12);
    }

    #[test]
    fn oblique_views_keep_z_up_and_are_right_handed() {
        let c = Camera::new(
            [0.0; 3],
            [8.0, 8.0, 16.0],
            [-0.5, -0.7, 0.5],
            64,
            &Framing::default(),
        )
        .unwrap();
        assert!(c.up.z > 0.0 && c.right.z.abs() < 1e-12);
        assert!((c.right.cross(c.up) - c.view).length() < 1e-12);
        // Every corner of the box projects inside the image.
        let half = c.pixel * 32.0;
        for i in 0..8 {
            let p = DVec3::new(
                (i & 1) as f64 * 8.0,
                (i >> 1 & 1) as f64 * 8.0,
                (i >> 2) as f64 * 16.0,
            ) - c.centre;
            assert!(p.dot(c.right).abs() <= half && p.dot(c.up).abs() <= half);
        }
        assert!(Camera::new([0.0; 3], [8.0; 3], [0.0, 0.0, 0.0], 64, &Framing::default()).is_err());
        assert!(Camera::new(
            [0.0; 3],
            [8.0; 3],
            [f64::NAN, 0.0, 1.0],
            64,
            &Framing::default()
        )
        .is_err());
        // Huge and tiny components give the view of the same direction.
        let unit =
            Camera::new([0.0; 3], [8.0; 3], [1.0, 0.0, 0.0], 64, &Framing::default()).unwrap();
        for v in [[1e200, 0.0, 0.0], [1e308, 0.0, 0.0], [1e-310, 0.0, 0.0]] {
            assert_eq!(
                Camera::new([0.0; 3], [8.0; 3], v, 64, &Framing::default()).unwrap(),
                unit,
                "{v:?}"
            );
        }
        // A box away from the origin is centred.
        let c = Camera::new(
            [10.0, 20.0, 30.0],
            [12.0, 22.0, 32.0],
            [0.0, 0.0, 1.0],
            8,
            &Framing::default(),
        )
        .unwrap();
        assert_eq!(c.centre, DVec3::new(11.0, 21.0, 31.0));
    }

    #[test]
    fn up_zoom_and_axes() {
        let f = Framing::default();
        let boxed = |v: [f64; 3], f: &Framing| Camera::new([0.0; 3], [8.0; 3], v, 64, f);
        // Up along world +x for a view along +z: +x is up, so right is -y.
        let c = boxed(
            [0.0, 0.0, 1.0],
            &Framing {
                up: Some([2.0, 0.0, 0.0]),
                ..f
            },
        )
        .unwrap();
        assert_eq!((c.up, c.right), (DVec3::X, -DVec3::Y));
        // Zoom 2 halves the pixel.
        let z = boxed([0.0, 0.0, 1.0], &Framing { zoom: 2.0, ..f }).unwrap();
        let one = boxed([0.0, 0.0, 1.0], &f).unwrap();
        assert_eq!(z.pixel * 2.0, one.pixel);
        // Refused: up parallel to the view, zero or not finite; zoom <= 0 or not finite.
        for (up, want) in [
            ([0.0, 0.0, -3.0], "parallel"),
            ([0.0, 0.0, 0.0], "zero length"),
            ([f64::NAN, 0.0, 0.0], "not finite"),
        ] {
            let e = boxed([0.0, 0.0, 1.0], &Framing { up: Some(up), ..f }).unwrap_err();
            assert!(e.to_string().contains(want), "{e}");
        }
        for zoom in [0.0, -1.0, f64::INFINITY] {
            assert!(boxed([0.0, 0.0, 1.0], &Framing { zoom, ..f }).is_err());
        }
        // Voxel x along world z, y along world x, z along world y: the world view +z is
        // the voxel frame's +x, and world up (+y here, as the view is along z) its +z.
        let axes = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let r = boxed([0.0, 0.0, 1.0], &Framing { axes, ..f }).unwrap();
        assert_eq!((r.view, r.up), (DVec3::X, DVec3::Z));
        assert_eq!(to_axes(&IDENTITY, [0.3, -2.0, 1e-300]), [0.3, -2.0, 1e-300]);
    }
}
