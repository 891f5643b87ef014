"""The Mitsuba base both render wings stand on: variants, plugin dicts, the scene translation and spectral textures."""
