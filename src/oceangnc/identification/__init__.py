"""System identification: first-order (Nomoto/speed) models from trials, augmented-state EKF."""
