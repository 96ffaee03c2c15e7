//! One scale for all variants of a sweep: the frames of every variant are drawn with the same
//! displacement magnification (the largest that is safe for all of them: the smallest of
//! their own automatic factors, or the explicit one they share) and the same stress colour
//! range (the union of their ranges), so a colour or a drawn displacement means the same in
//! every variant. Kept beside each variant's results ([`PICTURE_SCALE`]) so that `linkage
//! render` and the report use it again.

use crate::linkage::Interrupt;
use crate::render::colour_scale::round_up;
use crate::render::format_si;
use crate::render::gltf::write_gltf;
use crate::render::{draw_run, stored_time, RenderError, RenderOptions, RunExtent};
use crate::scene::atomic_file::write_atomically;
use crate::scene::{PlotSettings, RunResults, StoredRun};
use crate::Real;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The file in a sweep variant's results folder that keeps its [`SharedScale`].
pub const PICTURE_SCALE: &str = "picture_scale.json";

/// The magnification and colour ranges the frames of several variants of one sweep share.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SharedScale {
    /// Displacements are drawn this many times larger than they are (the smallest of the
    /// variants' own factors).
    pub magnification: Real,
    /// Largest |member axial stress| over all variants (line art colours), Pa.
    pub stress_limit: Real,
    /// Largest |mean member stress at a node| over all variants (surface colours), Pa.
    pub node_stress_limit: Real,
    /// Largest |stress of the most stressed member at a node| over all variants, Pa.
    pub node_peak_limit: Real,
    /// How many variants share it.
    pub variants: usize,
}

impl SharedScale {
    /// The scale of the variants whose own extents (each measured with the variant's own
    /// magnification, automatic or explicit) are `extents`: the smallest magnification, the
    /// largest of each colour limit. `None` without extents.
    pub fn of(extents: &[RunExtent]) -> Option<SharedScale> {
        let first = extents.first()?;
        let mut s = SharedScale {
            magnification: first.magnification,
            stress_limit: 0.0,
            node_stress_limit: 0.0,
            node_peak_limit: 0.0,
            variants: extents.len(),
        };
        for e in extents {
            s.magnification = s.magnification.min(e.magnification);
            s.stress_limit = s.stress_limit.max(e.stress_limit);
            s.node_stress_limit = s.node_stress_limit.max(e.node_stress_limit);
            s.node_peak_limit = s.node_peak_limit.max(e.node_peak_limit);
        }
        Some(s)
    }

    /// The extent of `run` drawn with this scale: measured at the shared magnification (the
    /// camera box fits the shape so magnified), with the shared colour limits.
    pub fn extent_of(&self, run: &RunResults) -> RunExtent {
        RunExtent {
            stress_limit: self.stress_limit,
            node_stress_limit: self.node_stress_limit,
            node_peak_limit: self.node_peak_limit,
            shared_by: Some(self.variants),
            ..RunExtent::of_run(run, Some(self.magnification))
        }
    }

    /// The scale as the report states it: the magnification and the colour ranges (rounded
    /// up as the colour bars are).
    pub fn describe(&self) -> String {
        let range = |limit: Real| {
            let s = format_si(round_up(limit), "Pa");
            format!("from −{s} to +{s}")
        };
        let mut text = format!(
            "the frames of the {} variants share one scale: displacements drawn ×{}",
            self.variants, self.magnification
        );
        if self.stress_limit > 0.0 {
            text.push_str(&format!(
                ", member axial stress colours {}",
                range(self.stress_limit)
            ));
        }
        if self.node_stress_limit > 0.0 {
            text.push_str(&format!(
                ", surface colours (mean member stress at nodes) {}",
                range(self.node_stress_limit)
            ));
        }
        text
    }

    /// The scale kept in the results folder `dir` ([`PICTURE_SCALE`]), if any (a file that
    /// does not read counts as none).
    pub fn read(dir: &Path) -> Option<SharedScale> {
        std::fs::read(dir.join(PICTURE_SCALE))
            .ok()
            .and_then(|b| serde_json::from_slice(&b).ok())
    }

    /// Keep this scale in the results folder `dir` ([`PICTURE_SCALE`], atomically).
    pub fn write(&self, dir: &Path) -> Result<(), RenderError> {
        let path = dir.join(PICTURE_SCALE);
        let text = serde_json::to_vec_pretty(self).map_err(|e| RenderError::Write {
            path: path.clone(),
            source: std::io::Error::other(e),
        })?;
        write_atomically(&path, &text).map_err(|source| RenderError::Write { path, source })
    }
}

/// One variant of a sweep to draw with the shared scale: its results folder, how its scene
/// asks its frames drawn, and whether it asks for the glTF animation.
#[derive(Clone, Debug)]
pub struct VariantPictures {
    /// The variant's results folder (`DIR/<scene>/<k>`).
    pub dir: PathBuf,
    /// Its scene's picture options (`magnification`: the explicit one, or `None`).
    pub options: RenderOptions,
    /// Write `anim.glb` too.
    pub gltf: bool,
}

/// Draw the frames (and GIF, and glTF animation when asked) of the `variants` of one sweep
/// with one [`SharedScale`], kept in each variant's folder. Each variant's stored steps are
/// read twice (once to measure, once to draw), one variant at a time. Returns the scale, or
/// `None` (nothing drawn, a scale kept from an earlier batch removed) for fewer than two
/// variants.
pub fn draw_with_shared_scale(
    variants: &[VariantPictures],
    stop: Interrupt,
) -> Result<Option<SharedScale>, RenderError> {
    if variants.len() < 2 {
        for v in variants {
            let _ = std::fs::remove_file(v.dir.join(PICTURE_SCALE));
        }
        return Ok(None);
    }
    let read = |dir: &Path| -> Result<RunResults, RenderError> {
        Ok(StoredRun::open(dir)?.read_all_until(stop)?)
    };
    let mut extents = Vec::with_capacity(variants.len());
    for v in variants {
        extents.push(RunExtent::of_run(&read(&v.dir)?, v.options.magnification));
    }
    let Some(scale) = SharedScale::of(&extents) else {
        return Ok(None);
    };
    for v in variants {
        let run = read(&v.dir)?;
        let options = RenderOptions {
            shared: Some(scale.clone()),
            step_fraction: v.options.step_fraction || PlotSettings::read(&v.dir).step_fraction,
            interrupt: stop,
            ..v.options.clone()
        };
        scale.write(&v.dir)?;
        draw_run(&run, &v.dir, &options)?;
        if v.gltf {
            write_gltf(&run, &v.dir, scale.magnification, stored_time)?;
        }
    }
    Ok(Some(scale))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn extent(magnification: Real, stress: Real) -> RunExtent {
        let run = RunResults {
            model: crate::scene::ModelFile {
                scene: "s".into(),
                bodies: Vec::new(),
                obstacles: Vec::new(),
                up: None,
            },
            steps: Vec::new(),
            digits: 4,
        };
        RunExtent {
            stress_limit: stress,
            node_stress_limit: 2.0 * stress,
            node_peak_limit: 3.0 * stress,
            ..RunExtent::of_run(&run, Some(magnification))
        }
    }

    #[test]
    fn the_smallest_magnification_and_the_largest_colour_limits() {
        let s =
            SharedScale::of(&[extent(500.0, 2e6), extent(50.0, 7e6), extent(200.0, 1e6)]).unwrap();
        assert_eq!(
            s,
            SharedScale {
                magnification: 50.0,
                stress_limit: 7e6,
                node_stress_limit: 14e6,
                node_peak_limit: 21e6,
                variants: 3,
            }
        );
        assert_eq!(SharedScale::of(&[]), None);
        assert_eq!(
            s.describe(),
            "the frames of the 3 variants share one scale: displacements drawn ×50, member axial \
             stress colours from −8.00 MPa to +8.00 MPa, surface colours (mean member stress at nodes) \
             from −15.0 MPa to +15.0 MPa"
        );
    }
}
