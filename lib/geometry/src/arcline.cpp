// Placeholder: arcline (Dubins) discretization, bit-identical to the devkit (in progress).
