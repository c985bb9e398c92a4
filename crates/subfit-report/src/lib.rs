//! What a fit is shown by (DESIGN.md §2 `subfit-report`): it formats and draws what the
//! measurer (`subfit-measure`) measured, and measures nothing itself.
//!
//! * [`color`]: the papers' error colours (Cheng 2007 §IV-D).
//! * [`plot`]: deterministic SVG line charts.
//! * [`html`]: self-contained report pages (report.html) around a three.js viewer, bundled
//!   only with the cargo feature `viewer` (which runs npm at build time; see `build.rs`).
//! * [`preview`]: a CPU rasterizer for `preview.png` (error colours, cage wireframe, colour bar).
//!
//! Nothing here prints or touches files.

pub mod color;
pub mod html;
pub mod plot;
pub mod preview;

pub use color::error_color;
pub use preview::{
    preview_png, render as render_preview, render_polymesh as render_preview_polymesh, ColorBar,
    Image, PreviewError, PreviewOptions, Projection, UpAxis, View, Wireframe,
};
