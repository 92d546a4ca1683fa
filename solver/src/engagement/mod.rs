//! Tool–workpiece engagement over time and flute-count recommendation (spec: engagement.md; seed 003). Not built yet.
