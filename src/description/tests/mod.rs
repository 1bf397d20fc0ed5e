//! The description layer's tests that look inside a built scene: the `auto` curve shape's
//! share-out between ribbons and tubes, and edits of a built scene that keep its BVH.

mod edits;
mod ribbons;
