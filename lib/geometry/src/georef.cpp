// Placeholder: georeferencing (GeographicLib) lands with the reader.
