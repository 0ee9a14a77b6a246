"""The default light rig of the preview: a key sphere light, a tube light and a fill."""

from __future__ import annotations

from matedit.shading.lights import Light


def default_rig() -> list[Light]:
    return [
        Light(kind="sphere", position=(2.4, 2.8, 3.0), color=(1.0, 0.96, 0.9), intensity=18.0,
              influence_radius=25.0, source_radius=0.3),
        Light(kind="tube", position=(-2.8, 1.6, -2.4), direction=(0.0, 1.0, 0.0),
              color=(0.75, 0.85, 1.0), intensity=10.0, influence_radius=25.0,
              source_radius=0.04, source_length=1.6),
        Light(kind="point", position=(-3.0, 0.4, 3.0), color=(1.0, 1.0, 1.0), intensity=3.0,
              influence_radius=25.0),
    ]
