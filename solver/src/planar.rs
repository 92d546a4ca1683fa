//! Plane (2-D) geometry shared by the contour and engagement solvers. Not built yet.
