//! Chord error from the controller's block processing time (spec: chord.md; seed 001). Not built yet.
