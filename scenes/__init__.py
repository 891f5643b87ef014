"""spectrinsic.scenes: scenes as plain data (geometry arrays + records naming spectra)."""

from spectrinsic.scenes.model import Camera, Light, Material, Mesh, Scene, scene_hash, scene_to_dict

__all__ = ["Camera", "Light", "Material", "Mesh", "Scene", "scene_hash", "scene_to_dict"]
