//! (being built) The comparison harness: every sphere method and the reference on the same scene.
