"""PIS set export: renders a Blender scene's parameter space with Cycles into a ray-traced set
(format-spec/RAYSET.md) that pis-pack packs, with the glTF and scene.toml beside it.

In Blender: Render Properties > PIS set. Headless: `python3 -m pis_blender SCENE.blend -o SET`
(the `bpy` module) or `blender -b SCENE.blend --python-expr "import pis_blender as p;
p.register(); p.export_set(bpy.context.scene, 'SET')"`.
"""

bl_info = {
    "name": "PIS set export",
    "author": "PIS",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "Properties > Render > PIS set",
    "description": "Render a parameter space with Cycles into a PIS ray-traced set",
    "category": "Render",
}


def register():
    from . import props, ui

    props.register()
    ui.register()


def unregister():
    from . import props, ui

    ui.unregister()
    props.unregister()


def export_set(scene, out_dir, progress=lambda line, done: print(line), keep_halves=False, points=None):
    """Renders `scene`'s parameter space into the set folder `out_dir` and returns a report;
    `progress(line, done)` hears of each point, `done` the share of points rendered;
    `keep_halves` leaves a denoised set's halves in `out_dir/.halves`; `points` renders only
    the first that many points."""
    from . import export

    return export.export_set(scene, out_dir, progress, keep_halves, points)
