//! `sahara-render`: Sahara's renderer. It knows meshes as plain arrays,
//! never as files.

pub mod mesh;
