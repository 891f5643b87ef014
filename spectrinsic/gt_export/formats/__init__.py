"""File formats of a sample's data: OpenEXR layers, PNG images and file-name-safe names."""
