//! Pictures of stored results: PNG frames and a GIF of a run, 2D line art and shaded 3D
//! patches, the glTF animation and the report's 3D viewer.

pub use self::animated_run::{
    evenly_spaced, stored_time, AnimatedBody, AnimatedObstacle, AnimatedRun, AnimationFrame,
    BodyShape, FrameBudget, FRAME_RATE,
};
pub use self::camera::{Camera, View, FIELD_OF_VIEW};
pub use self::colour_scale::{
    colour_at, format_si, ColourScale, Rgb, BODY_COLOURS, CONTACT_ORANGE, CRACK_RED, FORCE_BLUE,
    OBSTACLE_FILL, OBSTACLE_SURFACE, SUPPORT_TEAL,
};
pub use self::contact_magnification::{contact_magnification, round_factors_down};
pub use self::error::RenderError;
pub use self::extent::{auto_magnification, RunExtent};
pub use self::frame::Frame;
pub use self::gif::{EncodedFrame, GifAnimation, GifPalette};
pub use self::gif_timing::{pace_label, timed_delays};
pub use self::options::{Colouring, Projection, RenderOptions, StepSelection};
pub use self::picture::{camera_for, draw_frame, frame_primitives, view_for, viewport_for};
pub use self::primitives::{paint, Layer, Mesh, MeshKind, Primitive};
pub use self::raster::{Lighting, RasterVertex, Rasteriser, PLANE_ALPHA, VEIL_ALPHA};
pub use self::replot::{
    read_summary, redraw_plots, redraw_plots_of, redraw_report, redraw_report_of, ReplotError,
};
pub use self::run_pictures::{
    draw_read_run_to, draw_run, read_run_to_render, render_run, render_run_to, select_steps,
    PictureWriter, RenderReport,
};
pub use self::shared_scale::{draw_with_shared_scale, SharedScale, VariantPictures, PICTURE_SCALE};

mod animated_run;
mod camera;
mod colour_scale;
mod contact_magnification;
mod cracks;
mod deformed_body;
mod draw2d;
mod draw3d;
mod error;
mod extent;
mod frame;
mod gif;
mod gif_timing;
pub mod gltf;
mod markers;
mod obstacles;
mod options;
mod outline;
mod overlay;
mod picture;
pub mod plots;
mod primitives;
mod raster;
mod replot;
pub mod report;
mod run_pictures;
mod shared_scale;
mod text;
pub mod viewer;
