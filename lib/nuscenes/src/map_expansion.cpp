// Placeholder (in progress).
