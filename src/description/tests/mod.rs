//! The description layer's tests that look inside a built scene: the `auto` curve shape's
//! share-out between ribbons and tubes, and a large groom's parts.

mod parts;
mod ribbons;
