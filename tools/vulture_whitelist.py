"""Names vulture cannot see used: frameworks call them, or set them for a library to read.

Read by `vulture` (pyproject.toml [tool.vulture], run by ./dev.sh test), never imported or
run. Each line names an attribute (`_.name`) another program uses; add a name here only with
the framework that uses it. Dead code is deleted, not listed.
"""

# ruff: noqa
# mypy: ignore-errors
_ = object()

# Qt calls these overrides of QGraphicsScene, QGraphicsView, QOpenGLWidget, QTreeWidget,
# QUndoCommand, QWidget and QDoubleSpinBox by name.
_.drawBackground
_.wheelEvent
_.contextMenuEvent
_.mergeWith
_.mimeTypes
_.initializeGL
_.resizeGL
_.paintGL
# QAbstractSpinBox/QDoubleSpinBox (matedit.app.fields.NumberSpin)
_.textFromValue
_.valueFromText
_.fixup
# QAbstractItemModel (matedit.app.texture_browser._FileModel: a drag copies, never moves)
_.supportedDragActions

# moderngl reads these attributes of its textures and contexts when they are set.
_.repeat_x
_.repeat_y
_.repeat_z
_.blend_func
_.front_face
_.cull_face

# pygltflib writes this material field; MaterialX's XmlReadOptions reads this option.
_.emissiveFactor
_.readXIncludeFunction
_.hwSpecularEnvironmentMethod  # MaterialX GenOptions (benchmarks/bench_materialx.py)
_.targetColorSpaceOverride  # MaterialX GenOptions (tests/mtlx_gpu.py)

# Python calls a module's __getattr__ for a missing name (PEP 562: matedit.compiler's lazy
# names), and a test replaces an object's __class__ to give it a subclass's methods.
_.__getattr__
_.__class__

# written through a property (MaterialCompiler.last_compile_ms), which vulture does not follow
_._last_compile_ms

# the viewport calls the render process's camera by name (ViewportWidget._do("camera.orbit"))
_.orbit
_.dolly
_._stop_render_processes  # registered with atexit (matedit/app/viewport.py)
