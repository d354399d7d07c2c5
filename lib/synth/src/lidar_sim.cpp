// Placeholder: sensor simulation lands here.
