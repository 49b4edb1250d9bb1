//! Bond (cylinder impostor) pass benchmark: being written this session; see docs/PERFORMANCE.md.
fn main() {}
