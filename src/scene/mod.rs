//! Scenes: directional lights, a Phong material and a parallel view, as the paper assumes
//! (light and view directions do not depend on the sample's position). Loaded from TOML and
//! validated; [`Scene::shade`] is the float light model that builds the maps and, evaluated
//! at the float-normalised gradient, gives the reference every error is measured against.

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub mod transfer;

use crate::geometry::{sym_dot, unit_direction};
use crate::toml_input::{self, Invalid};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Where the scene came from, for generated documentation: `scenes/standard.toml` for
    /// the built-in scenes, the file's name (without its directory, so output does not
    /// depend on where a command ran) for a file, empty for other text. Not a TOML key.
    #[serde(skip)]
    pub name: String,
    #[serde(default)]
    pub view: View,
    pub material: Material,
    #[serde(default, rename = "light")]
    pub lights: Vec<Light>,
    /// Opacity transfer function for volume rendering (`rmapgen volume`); not used by the
    /// shading itself, so sphere scenes leave it out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transfer: Option<transfer::Transfer>,
    /// How the host fills the maps from the light model: `"sample"` (the light model at each
    /// entry's direction, the paper) or `"lsq"` (least squares over a dense grid of
    /// directions, `model::map_fit`). A top-level key; commands' `--map-fit` overrides it.
    #[serde(default)]
    pub map_fit: crate::model::map_fit::MapFit,
    /// The surface colour every sample carries, `[r, g, b]` in 0..=1 (a top-level key, sent to
    /// the design as 8-bit RGB, [`Scene::color8`]). A scene with a colour needs the colour
    /// multiplier (`rmapgen fit` includes it, and its test image checks the three channels);
    /// without one the design delivers the intensity only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<[f64; 3]>,
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
pub const STANDARD_TOML: &str = include_str!("../../scenes/standard.toml");

/// A second scene (`scenes/two_lights.toml`): the map the double-buffer tests load through the
/// host port and swap in mid-stream.
pub const ALTERNATE_TOML: &str = include_str!("../../scenes/two_lights.toml");

/// A direction from input, checked: `key` is where it sits in the scene file
/// (`light[2].direction`), and the error names it.
pub fn check_direction(key: &str, d: [f64; 3]) -> Result<DVec3, Invalid> {
    let v = DVec3::from_array(d);
    if !v.is_finite() {
        return Err(Invalid::new(
            key,
            format!("{key} = {d:?} is not finite; give three finite numbers"),
        ));
    }
    unit_direction(v).ok_or_else(|| {
        Invalid::new(
            key,
            format!("{key} = {d:?} has zero length; a direction needs a non-zero component"),
        )
    })
}

fn check_coef(key: &str, x: f64) -> Result<(), Invalid> {
    if !x.is_finite() || x < 0.0 {
        return Err(Invalid::new(
            key,
            format!("{key} = {x} must be a finite number >= 0"),
        ));
    }
    Ok(())
}

impl Scene {
    /// The maps of this scene for a configuration, filled as its `map_fit` says.
    pub fn maps(&self, cfg: &crate::config::Config) -> crate::model::Maps {
        let p = self.prepared();
        crate::model::map_fit::contents(cfg, self.map_fit, |n| p.shade(n))
    }

    pub fn standard() -> Scene {
        Scene::from_toml_str(STANDARD_TOML)
            .expect("the standard scene is valid")
            .named("scenes/standard.toml")
    }

    pub fn alternate() -> Scene {
        Scene::from_toml_str(ALTERNATE_TOML)
            .expect("the alternate scene is valid")
            .named("scenes/two_lights.toml")
    }

    /// The scene with [`Scene::name`] set.
    pub fn named(mut self, name: &str) -> Scene {
        self.name = name.to_string();
        self
    }

    pub fn from_toml_str(text: &str) -> anyhow::Result<Scene> {
        Scene::from_toml_named(text, "scene")
    }

    /// Parses and validates a scene; errors are one line starting with `what` (e.g.
    /// `scene s.toml`), the line and column, and the key.
    pub fn from_toml_named(text: &str, what: &str) -> anyhow::Result<Scene> {
        let s: Scene = toml_input::parse(text, what)?;
        s.check().map_err(|e| toml_input::invalid(text, what, &e))?;
        Ok(s)
    }

    pub fn from_toml_file(path: &Path) -> anyhow::Result<Scene> {
        let text = toml_input::read(path, "scene")?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        Ok(Scene::from_toml_named(&text, &format!("scene {}", path.display()))?.named(&name))
    }

    /// Checks every value, naming the first bad one by its key.
    pub fn validate(&self) -> anyhow::Result<()> {
        self.check().map_err(|e| anyhow::anyhow!(e.message))
    }

    /// [`Scene::validate`] with the key of the bad value, to locate it in a file.
    pub fn check(&self) -> Result<(), Invalid> {
        check_direction("view.direction", self.view.direction)?;
        let m = &self.material;
        check_coef("material.ambient", m.ambient)?;
        check_coef("material.diffuse", m.diffuse)?;
        check_coef("material.specular", m.specular)?;
        check_coef("material.shininess", m.shininess)?;
        // The maps of a scene without lights are its ambient term alone, one value
        // everywhere: a scene that lost its [[light]] tables, not one meant so (an
        // ambient-only scene says it with a light of intensity 0).
        if self.lights.is_empty() {
            return Err(Invalid::new(
                "light",
                "no [[light]]: a scene has one or more lights, each a [[light]] table with a direction (for the ambient term alone, give a light of intensity 0)",
            ));
        }
        for (i, l) in self.lights.iter().enumerate() {
            check_direction(&format!("light[{i}].direction"), l.direction)?;
            check_coef(&format!("light[{i}].intensity"), l.intensity)?;
        }
        if let Some(t) = &self.transfer {
            t.validate()
                .map_err(|e| Invalid::new("transfer.points", format!("{e:#}")))?;
        }
        if let Some(c) = self.color {
            if c.iter().any(|x| !(0.0..=1.0).contains(x)) {
                return Err(Invalid::new(
                    "color",
                    format!("color = {c:?} must have three components in 0..=1"),
                ));
            }
        }
        Ok(())
    }

    /// The scene's colour as the 8-bit RGB the colour multiplier takes (round half up), or
    /// `None` for a scene without colour.
    pub fn color8(&self) -> Option<[u32; 3]> {
        let max = ((1u32 << crate::config::COLOR_BITS) - 1) as f64;
        self.color
            .map(|c| c.map(|x| (x * max + 0.5).floor() as u32))
    }

    /// A scene prepared for fast evaluation: unit vectors, and the lights and terms that
    /// contribute nothing dropped: lights of intensity 0, every light when the material has
    /// neither diffuse nor specular, the specular term when its coefficient is 0 (see
    /// [`PreparedScene::shade`]); lights with the same direction become one light of their
    /// summed intensity (the light model is linear in a light's intensity). For a validated
    /// scene: a zero or non-finite direction panics rather than dropping the light.
    pub fn prepared(&self) -> PreparedScene {
        let m = &self.material;
        let mut lights: Vec<(DVec3, f64)> = Vec::new();
        for l in &self.lights {
            if l.intensity <= 0.0 || (m.diffuse <= 0.0 && m.specular <= 0.0) {
                continue;
            }
            let d = unit_direction(DVec3::from_array(l.direction)).expect(VALIDATED);
            match lights.iter_mut().find(|(e, _)| *e == d) {
                Some((_, i)) => *i += l.intensity,
                None => lights.push((d, l.intensity)),
            }
        }
        PreparedScene {
            view: unit_direction(DVec3::from_array(self.view.direction)).expect(VALIDATED),
            two_sided: self.view.two_sided,
            ambient: m.ambient,
            diffuse: m.diffuse,
            specular: m.specular,
            shininess: m.shininess,
            lights,
        }
    }

    /// What building the maps evaluates, and what it leaves out, in one line: for `fit` and
    /// the tests.
    pub fn terms(&self) -> String {
        let p = self.prepared();
        let mut used = Vec::new();
        if p.ambient > 0.0 {
            used.push("ambient".to_string());
        }
        if !p.lights.is_empty() {
            if p.diffuse > 0.0 {
                used.push("diffuse".to_string());
            }
            if p.specular > 0.0 {
                used.push(format!("specular (shininess {})", p.shininess));
            }
        }
        let skipped = self.lights.len() - p.lights.len();
        let mut s = format!(
            "{} of {} light(s), terms: {}",
            p.lights.len(),
            self.lights.len(),
            if used.is_empty() {
                "none".to_string()
            } else {
                used.join(" + ")
            }
        );
        if skipped > 0 {
            s.push_str(&format!(
                "; {skipped} light(s) skipped (intensity 0, no diffuse or specular, or merged with a light of the same direction)"
            ));
        }
        if p.specular <= 0.0 && self.material.specular <= 0.0 && !p.lights.is_empty() {
            s.push_str("; no specular term");
        }
        s
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

const VALIDATED: &str =
    "a validated scene (Scene::validate refuses zero and non-finite directions)";

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
    use crate::geometry::sym_normalize;

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
        // No light at all: refused, the file named; a light of intensity 0 is the way to say
        // ambient alone, and its maps are the ambient term everywhere.
        assert_eq!(
            bad(mat),
            "scene: no [[light]]: a scene has one or more lights, each a [[light]] table with a direction (for the ambient term alone, give a light of intensity 0)"
        );
        let e = Scene::from_toml_named(mat, "scene s.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("scene s.toml: no [[light]]"), "{e}");
        let ambient =
            Scene::from_toml_str(&format!("{mat}[[light]]\ndirection=[0,0,1]\nintensity=0\n"))
                .unwrap();
        assert!(ambient.prepared().lights.is_empty());
        assert_eq!(ambient.shade(DVec3::new(0.6, 0.0, 0.8)), 0.1);
        assert_eq!(ambient.shade(DVec3::Z), 0.1);
    }

    #[test]
    fn optional_transfer_function() {
        assert_eq!(Scene::standard().transfer, None);
        let mat = "[material]\nambient=0.1\ndiffuse=0.6\nspecular=0.3\nshininess=20\n[[light]]\ndirection=[1,1,2]\n";
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
    #[test]
    fn prepared_drops_and_merges_what_contributes_nothing() {
        let mat = "[material]\nambient=0.1\ndiffuse=0.6\nspecular=0.3\nshininess=20\n";
        let full = Scene::from_toml_str(&format!(
            "{mat}[[light]]\ndirection=[1,1,2]\nintensity=0.25\n\
             [[light]]\ndirection=[-1,0,1]\nintensity=0\n\
             [[light]]\ndirection=[2,2,4]\nintensity=0.5\n"
        ))
        .unwrap();
        let one = Scene::from_toml_str(&format!(
            "{mat}[[light]]\ndirection=[1,1,2]\nintensity=0.75\n"
        ))
        .unwrap();
        let p = full.prepared();
        assert_eq!(p.lights.len(), 1, "{:?}", p.lights);
        assert_eq!(p.lights[0].1, 0.75);
        // The same light model as the full sum, and the same one as the one-light scene.
        let mut rng = crate::rng::SplitMix64::new(3);
        for _ in 0..500 {
            let mut c = || rng.below(2001) as f64 / 1000.0 - 1.0;
            let n = DVec3::new(c(), c(), c());
            if n.length() < 1e-3 {
                continue;
            }
            let n = sym_normalize(n);
            let by_light: f64 = 0.1
                + full
                    .lights
                    .iter()
                    .map(|l| {
                        let ls = sym_normalize(DVec3::from_array(l.direction));
                        let nl = sym_dot(n, ls);
                        if nl <= 0.0 {
                            return 0.0;
                        }
                        let rv = sym_dot(2.0 * nl * n - ls, DVec3::Z);
                        l.intensity * (0.6 * nl + 0.3 * rv.max(0.0).powf(20.0))
                    })
                    .sum::<f64>();
            assert!((p.shade(n) - by_light).abs() < 1e-12);
            assert_eq!(p.shade(n), one.prepared().shade(n));
        }
        let t = full.terms();
        assert!(
            t.starts_with("1 of 3 light(s), terms: ambient + diffuse + specular")
                && t.contains("2 light(s) skipped"),
            "{t}"
        );
        let diffuse = Scene::from_toml_str(
            "[material]\nambient=0.1\ndiffuse=0.9\nspecular=0\nshininess=1\n[[light]]\ndirection=[1,1,2]\n",
        )
        .unwrap();
        assert_eq!(
            diffuse.terms(),
            "1 of 1 light(s), terms: ambient + diffuse; no specular term"
        );
        let dark = Scene::from_toml_str(
            "[material]\nambient=0.2\ndiffuse=0\nspecular=0\nshininess=1\n[[light]]\ndirection=[1,1,2]\n",
        )
        .unwrap();
        assert!(dark.prepared().lights.is_empty());
    }

    #[test]
    fn colour_is_optional_and_checked() {
        let mat = "[material]\nambient=0.1\ndiffuse=0.6\nspecular=0.3\nshininess=20\n[[light]]\ndirection=[1,1,2]\n";
        assert_eq!(Scene::standard().color8(), None);
        let s = Scene::from_toml_str(&format!("color = [1.0, 0.5, 0.0]\n{mat}")).unwrap();
        assert_eq!(s.color8(), Some([255, 128, 0]));
        let e = Scene::from_toml_str(&format!("color = [1.5, 0.5, 0.0]\n{mat}")).unwrap_err();
        assert!(e.to_string().contains("0..=1"), "{e}");
    }
}
