// Placeholder until the synth module lands.
