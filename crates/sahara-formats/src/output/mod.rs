//! Files out: images ([`image`]: PNG and EXR, with layers), a rendered
//! frame's image with its metadata, passes and list of names ([`frame`]),
//! render parts for the farm ([`part`]: a piece of a frame and its exact
//! sums, as EXR), each written atomically ([`atomic`]: a failed write
//! leaves the old file).

pub(crate) mod atomic;
pub(crate) mod frame;
pub(crate) mod image;
pub(crate) mod part;
