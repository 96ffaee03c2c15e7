//! What a picture is drawn with: frame size, camera, projection, colouring, steps.

use crate::linkage::Interrupt;
use crate::render::RenderError;
use crate::scene::{PictureSettings, MAX_FRAME_SIDE};
use crate::Real;
use std::str::FromStr;

/// How 3D points are projected onto the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    /// Parallel projection: sizes do not shrink with distance (the default for 2D).
    Orthographic,
    /// Central projection with a 30° field of view (the default for 3D).
    Perspective,
}

impl FromStr for Projection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "orthographic" | "ortho" => Ok(Projection::Orthographic),
            "perspective" | "persp" => Ok(Projection::Perspective),
            _ => Err(format!(
                "projection {s:?}: give \"orthographic\" or \"perspective\""
            )),
        }
    }
}

/// What sets the colour of members and surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colouring {
    /// Axial stress on a diverging scale: compression blue, tension red (with a colour bar);
    /// a 3D surface by the mean stress of the members at each node.
    Stress,
    /// As `Stress`, but a 3D surface by the stress of the most stressed member at each node
    /// (the value of largest magnitude), so peaks show; 2D members as `Stress`.
    MaxStress,
    /// One neutral colour: shape and shading only (overloaded members stay black).
    Plain,
}

impl FromStr for Colouring {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "stress" => Ok(Colouring::Stress),
            "max-stress" | "max_stress" => Ok(Colouring::MaxStress),
            "plain" | "none" => Ok(Colouring::Plain),
            _ => Err(format!(
                "colouring {s:?}: give \"stress\", \"max-stress\" or \"plain\""
            )),
        }
    }
}

/// Which stored steps to draw.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StepSelection {
    /// Every stored step.
    All,
    /// The last stored step only.
    Last,
    /// These step numbers (each must be stored).
    List(Vec<usize>),
}

impl FromStr for StepSelection {
    type Err = String;
    /// `all`, `last`, or a comma-separated list of step numbers and ranges: `0,3,5-8`.
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!("steps {s:?}: give \"all\", \"last\" or step numbers and ranges like 0,3,5-8")
        };
        match s {
            "all" => return Ok(StepSelection::All),
            "last" => return Ok(StepSelection::Last),
            _ => {}
        }
        let mut steps = Vec::new();
        for part in s.split(',') {
            let part = part.trim();
            if let Some((a, b)) = part.split_once('-') {
                let a: usize = a.trim().parse().map_err(|_| bad())?;
                let b: usize = b.trim().parse().map_err(|_| bad())?;
                if b < a {
                    return Err(bad());
                }
                steps.extend(a..=b);
            } else {
                steps.push(part.parse().map_err(|_| bad())?);
            }
        }
        steps.sort_unstable();
        steps.dedup();
        Ok(StepSelection::List(steps))
    }
}

/// How to draw a stored run: frame size, camera, magnification, colouring, which steps and
/// which files. Angles in degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height, pixels.
    pub height: u32,
    /// Camera azimuth about the vertical (+y) axis, degrees from +z towards +x
    /// (`None`: 0 for 2D scenes, 35 for 3D).
    pub azimuth: Option<Real>,
    /// Camera elevation above the x–z plane, degrees (`None`: 0 for 2D, 25 for 3D).
    pub elevation: Option<Real>,
    /// Zoom factor over the view that fits the whole run (1: fit).
    pub zoom: Real,
    /// Projection (`None`: orthographic for 2D, perspective for 3D).
    pub projection: Option<Projection>,
    /// Displacement magnification (`None`: automatic, 1 unless displacements are tiny).
    pub magnification: Option<Real>,
    /// Colouring of members and surfaces.
    pub colouring: Colouring,
    /// Draw the members over 3D surfaces.
    pub wireframe: bool,
    /// Which steps get frames.
    pub steps: StepSelection,
    /// Write `png/NNNN.png`.
    pub png: bool,
    /// Write `anim.gif`.
    pub gif: bool,
    /// Samples per pixel side for the shaded surfaces (1–4; 2 gives smooth edges).
    pub supersampling: u32,
    /// Stops the drawing between frames once raised (never by default).
    pub interrupt: Interrupt,
    /// The results' load factor is the step fraction, not what the schedules say
    /// ([`crate::scene::PlotSettings::step_fraction`]): the title calls it so.
    pub step_fraction: bool,
    /// The magnification and colour ranges shared by the variants of a sweep (see
    /// [`crate::render::SharedScale`]): used instead of the run's own (and of
    /// `magnification`). `None`: the run's own.
    pub shared: Option<crate::render::SharedScale>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 1280,
            height: 720,
            azimuth: None,
            elevation: None,
            zoom: 1.0,
            projection: None,
            magnification: None,
            colouring: Colouring::Stress,
            wireframe: false,
            steps: StepSelection::All,
            png: true,
            gif: true,
            supersampling: 2,
            interrupt: Interrupt::default(),
            step_fraction: false,
            shared: None,
        }
    }
}

impl RenderOptions {
    /// The options a scene's `[output]` table asks for.
    pub fn from_settings(s: &PictureSettings) -> Self {
        RenderOptions {
            width: s.width,
            height: s.height,
            azimuth: s.azimuth,
            elevation: s.elevation,
            magnification: s.magnification,
            colouring: s
                .colour
                .as_deref()
                .and_then(|c| c.parse().ok())
                .unwrap_or(Colouring::Stress),
            png: s.png,
            gif: s.gif,
            ..RenderOptions::default()
        }
    }

    /// Check every value; the error says what to give instead.
    pub fn check(&self) -> Result<(), RenderError> {
        let bad = |message: String| Err(RenderError::Option { message });
        for (name, v) in [("width", self.width), ("height", self.height)] {
            if !(16..=MAX_FRAME_SIDE).contains(&v) {
                return bad(format!(
                    "{name} {v}: give a frame size from 16 to {MAX_FRAME_SIDE} pixels"
                ));
            }
        }
        if !(self.zoom.is_finite() && self.zoom > 0.0) {
            return bad(format!(
                "zoom {}: give a positive number (1 fits the whole run)",
                self.zoom
            ));
        }
        if let Some(m) = self.magnification {
            if !(m.is_finite() && m > 0.0) {
                return bad(format!(
                    "magnification {m}: give a positive number (1 draws displacements to scale)"
                ));
            }
        }
        if let Some(a) = self.azimuth {
            if !a.is_finite() {
                return bad(format!("azimuth {a}: give degrees"));
            }
        }
        if let Some(e) = self.elevation {
            if !(e.is_finite() && e.abs() <= 90.0) {
                return bad(format!("elevation {e}: give degrees from -90 to 90"));
            }
        }
        if !(1..=4).contains(&self.supersampling) {
            return bad(format!("supersampling {}: give 1 to 4", self.supersampling));
        }
        Ok(())
    }
}
