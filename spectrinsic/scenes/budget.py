"""One scene-wide budget of faces, vertices and texels, for every scene format.

A scene file may reference many meshes (ten references to one 200,000-face PLY; 300 glTF
nodes), each within a per-file limit, and still exhaust memory. So every reader (YAML, mesh
files, glTF/GLB, ``.blend``, Mitsuba XML) charges one :class:`SceneBudget` with what each part
*declares* before the part is loaded (a PLY or OFF header, OBJ lines counted, a glTF accessor's
``count``), and the first charge past a limit is refused in one line naming the file and the
count. Nothing larger than the budget is ever built.

Memory (measured on the 2-core dev machine: growth of ``ru_maxrss`` over
``load_scene_file`` of one grid PLY, reading and validation; ``docs/reliability-round-4.md``):
331 MiB at 50,000 faces, 598 MiB at 100,000, 1,111 MiB at 200,000, so about 520 MiB per
100,000 faces, most of it trimesh's ray index of the camera's view. :data:`MAX_FACES` =
250,000 faces bounds a scene near 1.4 GB.

Usage::

    budget = SceneBudget("room.yaml")
    budget.charge("mesh 'chair' (chair.ply)", faces=12_000, vertices=6_100)
    budget.charge("texture 'wood'", texels=256 * 256)
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import SceneError

__all__ = ["MAX_FACES", "MAX_VERTICES", "MAX_TEXELS", "SceneBudget"]

#: Most triangles of one scene, all its meshes together (see the module docstring's memory).
MAX_FACES = 250_000
#: Most vertices of one scene, all its meshes together (reading takes about 2.5 KiB per vertex:
#: a 10^6-vertex PLY took 2.5 GB); twice the faces' limit, as an unindexed mesh has 3 per face.
MAX_VERTICES = 500_000
#: Most texels of one scene, all its spectral textures together (16 textures of 256 x 256).
MAX_TEXELS = 16 * 256 * 256


@dataclass
class SceneBudget:
    """Running totals of one scene's faces, vertices and texels, refused past the limits.

    Attributes
    ----------
    source
        The scene file (or its name) every refusal names.
    faces, vertices, texels
        What has been charged so far.
    """

    source: str
    faces: int = 0
    vertices: int = 0
    texels: int = 0
    limits: tuple[int, int, int] = field(default=(MAX_FACES, MAX_VERTICES, MAX_TEXELS))

    def charge(self, what: str, *, faces: int = 0, vertices: int = 0, texels: int = 0) -> None:
        """Add one part's declared counts; raise :class:`SceneError` (one line naming
        :attr:`source`, *what* and the count) if a total passes its limit. Call it before the
        part is loaded."""
        totals = (self.faces + faces, self.vertices + vertices, self.texels + texels)
        self.faces, self.vertices, self.texels = totals  # kept past a refusal: later parts fail too
        for name, total, limit in zip(("faces", "vertices", "texels"), totals, self.limits):
            if total > limit:
                raise SceneError(
                    f"{self.source}: {what} brings the scene to {total:,} {name}; a scene "
                    f"holds at most {limit:,} {name} (simplify its meshes or textures)"
                )
