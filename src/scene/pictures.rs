//! What a run draws and exports besides its JSON results: `[output] png / gif / vtk` and the
//! picture options of the scene file (the CLI's `--png` and `--vtk` switch them on too).

use crate::scene::spec::OutputSpec;
use crate::scene::vtu_arrays::VtkEncoding;
use crate::Real;

/// Pictures and VTK files a run writes (see `docs/SCENES.md`, `[output]`).
#[derive(Clone, Debug, PartialEq)]
pub struct PictureSettings {
    /// Write `png/NNNN.png`, one frame per stored step.
    pub png: bool,
    /// Write `anim.gif`, one frame per stored step (default: as `png`).
    pub gif: bool,
    /// Write `vtk/NNNN.vtu` per stored step and `vtk/<scene>.pvd`.
    pub vtk: bool,
    /// Write `anim.glb`, the glTF 2.0 animation of the stored steps (`[output] gltf`).
    pub gltf: bool,
    /// How the `.vtu` files store their arrays (`[output] vtk_format`).
    pub vtk_encoding: VtkEncoding,
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// Displacement magnification; `None`: automatic (1 unless displacements are tiny).
    pub magnification: Option<Real>,
    /// Camera azimuth, degrees (3D; `None`: the default view).
    pub azimuth: Option<Real>,
    /// Camera elevation, degrees (3D; `None`: the default view).
    pub elevation: Option<Real>,
    /// What colours members and surfaces (`[output] colour`): "stress", "max-stress" or
    /// "plain" (`None`: "stress").
    pub colour: Option<String>,
    /// The unit direction drawn upwards in frames (`[output] up`, or opposite the scene's
    /// `gravity`): default +y.
    pub up: [Real; 3],
}

impl Default for PictureSettings {
    fn default() -> Self {
        PictureSettings {
            png: false,
            gif: false,
            vtk: false,
            gltf: false,
            vtk_encoding: VtkEncoding::Binary,
            width: 1280,
            height: 720,
            magnification: None,
            azimuth: None,
            elevation: None,
            colour: None,
            up: [0.0, 1.0, 0.0],
        }
    }
}

/// The values of `[output] colour`.
pub const COLOURS: [&str; 3] = ["stress", "max-stress", "plain"];

/// Largest frame side, pixels.
pub const MAX_FRAME_SIDE: u32 = 8192;

impl PictureSettings {
    /// Take "up" opposite `gravity` (m/s², one component per dimension) when it is not zero.
    pub fn up_against(&mut self, gravity: &[Real]) {
        let g: Vec<Real> = (0..3)
            .map(|k| gravity.get(k).copied().unwrap_or(0.0))
            .collect();
        let norm = g.iter().map(|x| x * x).sum::<Real>().sqrt();
        if norm > 0.0 && norm.is_finite() {
            self.up = [-g[0] / norm, -g[1] / norm, -g[2] / norm];
        }
    }

    /// Switch on PNG frames and the GIF (the CLI's `--png`).
    pub fn ask_png(&mut self) {
        self.png = true;
        self.gif = true;
    }

    /// Check the `[output]` picture keys; the error says what to give instead.
    pub fn from_spec(spec: &OutputSpec) -> Result<Self, String> {
        let d = PictureSettings::default();
        let png = spec.png.unwrap_or(false);
        let side = |key: &str, v: Option<u32>, default: u32| match v {
            None => Ok(default),
            Some(v) if (16..=MAX_FRAME_SIDE).contains(&v) => Ok(v),
            Some(v) => Err(format!(
                "[output] {key} = {v}: give a frame size from 16 to {MAX_FRAME_SIDE} pixels"
            )),
        };
        if let Some(m) = spec.magnification {
            if !(m.is_finite() && m > 0.0) {
                return Err(format!(
                    "[output] magnification = {m}: give a positive number (1 draws displacements to scale)"
                ));
            }
        }
        for (key, v) in [("azimuth", spec.azimuth), ("elevation", spec.elevation)] {
            if let Some(a) = v {
                if !a.is_finite() || (key == "elevation" && a.abs() > 90.0) {
                    return Err(format!(
                        "[output] {key} = {a}: give degrees (elevation from -90 to 90)"
                    ));
                }
            }
        }
        if let Some(c) = spec.colour.as_deref() {
            if !COLOURS.contains(&c) {
                return Err(format!(
                    "[output] colour = {c:?}: give \"stress\" (mean member stress at 3D nodes), \"max-stress\" (largest member stress at 3D nodes) or \"plain\""
                ));
            }
        }
        let up = match spec.up.as_deref() {
            None | Some("y") => [0.0, 1.0, 0.0],
            Some("x") => [1.0, 0.0, 0.0],
            Some("z") => [0.0, 0.0, 1.0],
            Some(u) => {
                return Err(format!(
                    "[output] up = {u:?}: give \"x\", \"y\" or \"z\" (the axis drawn upwards)"
                ))
            }
        };
        let vtk_encoding = match spec.vtk_format.as_deref() {
            None => VtkEncoding::Binary,
            Some(f) => VtkEncoding::parse(f).ok_or_else(|| {
                format!("[output] vtk_format = {f:?}: use \"binary\" (compressed, the default) or \"ascii\"")
            })?,
        };
        Ok(PictureSettings {
            png,
            gif: spec.gif.unwrap_or(png),
            vtk: spec.vtk.unwrap_or(false),
            gltf: spec.gltf.unwrap_or(false),
            vtk_encoding,
            width: side("width", spec.width, d.width)?,
            height: side("height", spec.height, d.height)?,
            magnification: spec.magnification,
            azimuth: spec.azimuth,
            elevation: spec.elevation,
            colour: spec.colour.clone(),
            up,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vtk_format_is_binary_by_default_and_a_wrong_one_is_named() {
        let spec = OutputSpec::default();
        let s = PictureSettings::from_spec(&spec).unwrap();
        assert_eq!(s.vtk_encoding, VtkEncoding::Binary);
        let spec = OutputSpec {
            vtk_format: Some("ascii".into()),
            ..Default::default()
        };
        let s = PictureSettings::from_spec(&spec).unwrap();
        assert_eq!(s.vtk_encoding, VtkEncoding::Ascii);
        let spec = OutputSpec {
            vtk_format: Some("xml".into()),
            ..Default::default()
        };
        let e = PictureSettings::from_spec(&spec).unwrap_err();
        assert!(
            e.contains("vtk_format = \"xml\"") && e.contains("\"ascii\""),
            "{e}"
        );
    }

    #[test]
    fn up_is_y_by_default_the_axis_given_or_opposite_gravity() {
        let up = |u: Option<&str>| {
            PictureSettings::from_spec(&OutputSpec {
                up: u.map(String::from),
                ..Default::default()
            })
        };
        assert_eq!(up(None).unwrap().up, [0.0, 1.0, 0.0]);
        assert_eq!(up(Some("z")).unwrap().up, [0.0, 0.0, 1.0]);
        assert_eq!(up(Some("x")).unwrap().up, [1.0, 0.0, 0.0]);
        let e = up(Some("-z")).unwrap_err();
        assert!(e.contains("up = \"-z\"") && e.contains("\"z\""), "{e}");
        // Gravity decides over the key: up is opposite it, a unit vector (3-4-5 triangle).
        let mut s = up(Some("z")).unwrap();
        s.up_against(&[3.0, -4.0]);
        assert_eq!(s.up, [-0.6, 0.8, -0.0]);
        // Zero gravity leaves it.
        s.up_against(&[0.0, 0.0, 0.0]);
        assert_eq!(s.up, [-0.6, 0.8, -0.0]);
    }
}
