"""Scenes: the TOML schema with its validation, meshes, and building a problem from them."""
