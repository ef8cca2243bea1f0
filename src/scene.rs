//! Scenes: directional lights, a Phong material and a parallel view, as the paper assumes
//! (light and view directions do not depend on the sample's position). Loaded from TOML and
//! validated; [`Scene::shade`] is the float light model that builds the maps and, evaluated
//! at the float-normalised gradient, gives the reference every error is measured against.

use anyhow::Context;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    #[serde(default)]
    pub view: View,
    pub material: Material,
    #[serde(default, rename = "light")]
    pub lights: Vec<Light>,
    /// Opacity transfer function for volume rendering (`rmapgen volume`); not used by the
    /// shading itself, so sphere scenes leave it out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<crate::volume::transfer::Transfer>,
    /// How the host fills the maps from the light model: `"sample"` (the light model at each
    /// entry's direction, the paper) or `"lsq"` (least squares over a dense grid of
    /// directions, `model::map_fit`). A top-level key; commands' `--map-fit` overrides it.
    #[serde(default)]
    pub map_fit: crate::model::map_fit::MapFit,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct View {
    /// Direction from the surface towards the viewer.
    #[serde(default = "default_view")]
    pub direction: [f64; 3],
    /// Light back faces as if their normal pointed towards the viewer.
    #[serde(default)]
    pub two_sided: bool,
}

fn default_view() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

impl Default for View {
    fn default() -> Self {
        View {
            direction: default_view(),
            two_sided: false,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    pub shininess: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    /// Direction from the surface towards the light.
    pub direction: [f64; 3],
    #[serde(default = "one")]
    pub intensity: f64,
}

fn one() -> f64 {
    1.0
}

/// The standard scene of the README and the tests, as shipped in `scenes/standard.toml`.
pub const STANDARD_TOML: &str = include_str!("../scenes/standard.toml");

/// A second scene (`scenes/two_lights.toml`): the map the double-buffer tests load through the
/// host port and swap in mid-stream.
pub const ALTERNATE_TOML: &str = include_str!("../scenes/two_lights.toml");

/// A dot product whose three products are added in ascending order, so that permuting the
/// axes of both vectors gives the identical float result. Map entries and the reference use it
/// so that an axis-swapped gradient under an axis-swapped scene shades bit-identically.
#[inline]
pub fn sym_dot(a: DVec3, b: DVec3) -> f64 {
    let (mut p, mut q, mut r) = (a.x * b.x, a.y * b.y, a.z * b.z);
    if p > q {
        std::mem::swap(&mut p, &mut q);
    }
    if q > r {
        std::mem::swap(&mut q, &mut r);
    }
    if p > q {
        std::mem::swap(&mut p, &mut q);
    }
    (p + q) + r
}

/// Normalisation with [`sym_dot`]: axis permutations commute with it exactly.
#[inline]
pub fn sym_normalize(v: DVec3) -> DVec3 {
    v / sym_dot(v, v).sqrt()
}

fn check_dir(what: &str, d: [f64; 3]) -> anyhow::Result<DVec3> {
    let v = DVec3::from_array(d);
    if !v.is_finite() {
        anyhow::bail!("{what} {d:?} is not finite");
    }
    if v.length() < 1e-12 {
        anyhow::bail!("{what} {d:?} has zero length");
    }
    Ok(sym_normalize(v))
}

fn check_coef(what: &str, x: f64) -> anyhow::Result<()> {
    if !x.is_finite() || x < 0.0 {
        anyhow::bail!("{what} = {x} must be a finite number >= 0");
    }
    Ok(())
}

impl Scene {
    pub fn standard() -> Scene {
        Scene::from_toml_str(STANDARD_TOML).expect("the standard scene is valid")
    }

    pub fn alternate() -> Scene {
        Scene::from_toml_str(ALTERNATE_TOML).expect("the alternate scene is valid")
    }

    pub fn from_toml_str(text: &str) -> anyhow::Result<Scene> {
        let s: Scene =
            toml::from_str(text).map_err(|e| anyhow::anyhow!("{}", e.message().trim()))?;
        s.validate()?;
        Ok(s)
    }

    pub fn from_toml_file(path: &Path) -> anyhow::Result<Scene> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read scene {}", path.display()))?;
        Scene::from_toml_str(&text).with_context(|| format!("bad scene {}", path.display()))
    }

    pub fn validate(&self) -> anyhow::Result<()> {
        check_dir("view direction", self.view.direction)?;
        let m = &self.material;
        check_coef("ambient", m.ambient)?;
        check_coef("diffuse", m.diffuse)?;
        check_coef("specular", m.specular)?;
        check_coef("shininess", m.shininess)?;
        for (i, l) in self.lights.iter().enumerate() {
            check_dir(&format!("light {} direction", i + 1), l.direction)?;
            check_coef(&format!("light {} intensity", i + 1), l.intensity)?;
        }
        if let Some(t) = &self.transfer {
            t.validate()?;
        }
        Ok(())
    }

    /// A scene prepared for fast evaluation: unit vectors, and the lights and terms that
    /// contribute nothing dropped.
    pub fn prepared(&self) -> PreparedScene {
        let m = &self.material;
        let lights = self
            .lights
            .iter()
            .filter(|l| l.intensity > 0.0 && (m.diffuse > 0.0 || m.specular > 0.0))
            .map(|l| (sym_normalize(DVec3::from_array(l.direction)), l.intensity))
            .collect();
        PreparedScene {
            view: sym_normalize(DVec3::from_array(self.view.direction)),
            two_sided: self.view.two_sided,
            ambient: m.ambient,
            diffuse: m.diffuse,
            specular: m.specular,
            shininess: m.shininess,
            lights,
        }
    }

    /// The light model at a unit normal (not clamped; map building and the reference clamp).
    pub fn shade(&self, n: DVec3) -> f64 {
        self.prepared().shade(n)
    }

    /// Whether the scene has a specular term that reaches the image.
    pub fn has_specular(&self) -> bool {
        self.material.specular > 0.0 && self.lights.iter().any(|l| l.intensity > 0.0)
    }
}

#[derive(Clone, Debug)]
pub struct PreparedScene {
    pub view: DVec3,
    pub two_sided: bool,
    pub ambient: f64,
    pub diffuse: f64,
    pub specular: f64,
    pub shininess: f64,
    pub lights: Vec<(DVec3, f64)>,
}

impl PreparedScene {
    /// Phong: ambient + sum over lights of intensity * (diffuse * max(0, n.l)
    /// + specular * max(0, r.v)^shininess), r = 2 (n.l) n - l, specular only where n.l > 0.
    #[inline]
    pub fn shade(&self, n: DVec3) -> f64 {
        let n = if self.two_sided && sym_dot(n, self.view) < 0.0 {
            -n
        } else {
            n
        };
        let mut i = self.ambient;
        for &(l, li) in &self.lights {
            let nl = sym_dot(n, l);
            if nl <= 0.0 {
                continue;
            }
            let mut c = self.diffuse * nl;
            if self.specular > 0.0 {
                let rv = sym_dot(2.0 * nl * n - l, self.view);
                if rv > 0.0 {
                    c += self.specular * rv.powf(self.shininess);
                }
            }
            i += li * c;
        }
        i
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_scene_loads() {
        let s = Scene::standard();
        assert_eq!(s.lights.len(), 1);
        // Facing the light head-on: ambient + diffuse + a specular below its peak.
        let l = DVec3::new(1.0, 1.0, 2.0).normalize();
        let v = s.shade(l);
        assert!(v > 0.7 && v <= 1.0, "{v}");
    }

    #[test]
    fn rejects_bad_values() {
        let bad = |t: &str| Scene::from_toml_str(t).unwrap_err().to_string();
        let mat = "[material]\nambient=0.1\ndiffuse=0.6\nspecular=0.3\nshininess=20\n";
        assert!(bad(&format!("{mat}[[light]]\ndirection=[0,0,0]\n")).contains("zero length"));
        assert!(bad(&format!("{mat}[[light]]\ndirection=[nan,0,1]\n")).contains("not finite"));
        assert!(bad(&mat.replace("shininess=20", "shininess=-1")).contains("shininess"));
        assert!(bad("[material\n").len() > 3);
    }

    #[test]
    fn optional_transfer_function() {
        assert_eq!(Scene::standard().transfer, None);
        let mat = "[material]\nambient=0.1\ndiffuse=0.6\nspecular=0.3\nshininess=20\n";
        let s =
            Scene::from_toml_str(&format!("{mat}[transfer]\npoints=[[10,0],[20,1]]\n")).unwrap();
        assert_eq!(s.transfer.unwrap().points, vec![[10.0, 0.0], [20.0, 1.0]]);
        let e = Scene::from_toml_str(&format!("{mat}[transfer]\npoints=[[20,0],[10,1]]\n"))
            .unwrap_err();
        assert!(e.to_string().contains("not monotonic"), "{e}");
        assert!(
            Scene::from_toml_str(&format!("{mat}[transfer]\npoint=[[10,0],[20,1]]\n")).is_err()
        );
    }
}
