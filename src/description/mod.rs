//! The scene description: the serde types of the RON scene format ([`schema`]) and the context
//! in which each type reads its own part of it ([`context`]: errors naming the file and the
//! field, checked numbers, paths, spectra, photometric amounts). Every type that builds itself
//! (lights, materials, the camera, meters and grids) reads its description through these; the
//! scene builder (`crate::scene`) only dispatches.

pub mod context;
pub mod material;
pub mod schema;
