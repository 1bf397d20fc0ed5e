//! The description layer's tests that look inside a built scene: the `auto` curve shape's
//! share-out between ribbons and tubes, edits of a built scene that keep its BVH, and a
//! large groom's parts.

mod edits;
mod parts;
mod ribbons;
