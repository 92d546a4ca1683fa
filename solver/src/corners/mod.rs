//! Layered contour milling with corner loops (spec: corners.md; seed 004). Not built yet.
