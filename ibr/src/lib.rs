//! Image-based rendering for Parallax: techniques that replace geometry with images where
//! that is cheaper (billboards, impostors, depth images, layered depth images).
//!
//! Rules: `ibr` builds on `engine` and never the reverse. IBR *data* (an impostor atlas, a
//! depth image) is kept apart from the code that bakes or draws it through the engine, so
//! the data can be built and tested without the rasterizer. The techniques land issue by
//! issue; until then this crate only fixes its place in the workspace.
