//! Machining-error prediction and path correction (spec: error-prediction.md; seed 002). Not built yet.
