"""The inspector: the selected node's documentation, inputs, values and settings.

Every edit becomes one command through `controller.push`; a slider drag pushes
each step with one merge id so it undoes as one step. Value edits are VALUE
changes (uniforms), so they never recompile. The panel rebuilds when the
selection or the node's ports change and only refreshes numbers on value
changes, so a drag in progress keeps its widgets.
"""

from __future__ import annotations

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QScrollArea,
    QVBoxLayout,
    QWidget,
)

from matedit.app import file_dialogs
from matedit.app.controller import DocumentController
from matedit.app.fields import (
    ColorField,
    FloatField,
    TextureField,
    VectorField,
    _spin,
    guard_wheel,
)
from matedit.app.paths import absolute_of, reference_for
from matedit.graph import nodes
from matedit.graph.commands import SetLabel, SetSetting, SetValue
from matedit.graph.model import ChangeEvent, ChangeKind, Node
from matedit.graph.nodes import MESH_UV, Port, Role, SettingDef, limit_problem, role_of
from matedit.graph.ports import normalize_channels
from matedit.graph.types import PortType, coerce_value

_COLOUR_WORDS = ("color", "colour", "tint", "albedo", "emissive", "basecolor")
_COMPONENTS = {"float": 1, "vec2": 2, "vec3": 3, "vec4": 4}


def is_colour(name: str, node_kind: str) -> bool:
    n = name.lower()
    return role_of(node_kind) == Role.COLOR_PARAMETER or any(w in n for w in _COLOUR_WORDS)



def _shown(value) -> str:
    if isinstance(value, list):
        return "(" + ", ".join(f"{x:g}" for x in value) + ")"
    return f"{value:g}"

class InspectorPanel(QScrollArea):
    """Shows and edits one node of the active document."""

    message = Signal(str)
    functionOpenRequested = Signal(str)
    docsRequested = Signal(str)  # a node kind's documentation
    textureSlotChosen = Signal(str, str, str)  # node, texture input, image file ("": clear)

    def __init__(self, controller: DocumentController, parent=None) -> None:
        super().__init__(parent)
        self.setWidgetResizable(True)
        self.setMinimumWidth(280)
        self.controller: DocumentController | None = None
        self.node_id: str | None = None
        self._fields: dict[tuple[str, str], QWidget] = {}  # ("value"|"setting", name) -> field
        self._ports_key: object = None
        self._shown: str | None = None  # the node the body was last built for
        self._rebuild_timer = QTimer(self)
        self._rebuild_timer.setSingleShot(True)
        self._rebuild_timer.setInterval(0)
        self._rebuild_timer.timeout.connect(self._rebuild_if_ports_changed)
        self.set_controller(controller)

    # --- wiring ----------------------------------------------------------------------------
    def set_controller(self, controller: DocumentController) -> None:
        if self.controller is controller:
            return
        if self.controller is not None:
            for sig, slot in self._connections():
                sig.disconnect(slot)
        self.controller = controller
        for sig, slot in self._connections():
            sig.connect(slot)
        self.node_id = None
        self.rebuild()

    def _connections(self):
        c = self.controller
        return [(c.changed, self._on_change), (c.analysed, self._on_analysed),
                (c.documentReplaced, self._on_replaced)]

    def show_node(self, node_id: str | None) -> None:
        if node_id is None and self.node_id is None and self._shown is None \
                and self.widget() is not None:
            return  # the hint shows already (a document opened: several "nothing selected")
        self.node_id = node_id
        self.rebuild()

    def set_selection(self, ids: list[str]) -> None:
        self.show_node(ids[0] if len(ids) == 1 else None)

    def _on_replaced(self) -> None:
        self.show_node(None)

    def _node(self) -> Node | None:
        if self.controller is None or self.node_id is None:
            return None
        return self.controller.document.graph.nodes.get(self.node_id)

    def _on_change(self, event: ChangeEvent) -> None:
        if self.node_id is None:
            return
        if self.node_id not in self.controller.document.graph.nodes:
            self.show_node(None)
            return
        touches = self.node_id in event.node_ids
        if event.kind == ChangeKind.VALUE and touches and event.what == "setting":
            self._rebuild_timer.start()  # e.g. a slider's range (ui_min, ui_max) changed
            self._ports_key = None
        elif event.kind == ChangeKind.VALUE and touches:
            self.refresh_values()
        elif event.kind == ChangeKind.STRUCTURAL and touches:
            self._rebuild_timer.start()
        elif event.kind == ChangeKind.LAYOUT and touches and event.what == "label":
            self._rebuild_timer.start()
        elif event.kind == ChangeKind.VALUE and any(k[0] == "slot" for k in self._fields):
            self.refresh_values()  # the image of a parameter wired into a texture slot

    def _on_analysed(self, _analysis) -> None:
        if self.node_id is not None:
            self._rebuild_timer.start()  # never rebuild inside a widget's own signal

    def _ports_signature(self) -> object:
        node = self._node()
        if node is None:
            return None
        a = self.controller.analysis
        ports = a.ports.get(node.id) if a else None
        connected = sorted(p for p in self.controller.document.graph.inputs_of(node.id))
        return (node.kind, node.label, repr(sorted(node.settings.items())),
                tuple((p.name, p.type) for p in ports.inputs) if ports else None,
                tuple(sorted((a.in_types.get(node.id) or {}).items())) if a else None,
                tuple(connected))

    def _rebuild_if_ports_changed(self) -> None:
        if self._ports_signature() != self._ports_key:
            self.rebuild()

    # --- building --------------------------------------------------------------------------
    def rebuild(self) -> None:
        # The same node rebuilt (an edit changed its ports): stay where the artist was.
        bar = self.verticalScrollBar()
        keep = bar.value() if self.node_id is not None and self.node_id == self._shown else 0
        self._shown = self.node_id
        self._fields.clear()
        self._build_body()
        if keep:
            self.widget().adjustSize()
            bar.setValue(keep)
            QTimer.singleShot(0, self, lambda: bar.setValue(keep))

    def _build_body(self) -> None:
        body = QWidget()
        lay = QVBoxLayout(body)
        lay.setContentsMargins(10, 8, 10, 8)
        lay.setSpacing(6)
        node = self._node()
        self._ports_key = self._ports_signature()
        if node is None:
            hint = QLabel("Select a node to edit it.\n\nRight-click the canvas or press Tab "
                          "to add nodes.")
            hint.setObjectName("emptyHint")
            hint.setWordWrap(True)
            lay.addWidget(hint)
            lay.addStretch(1)
            self.setWidget(body)
            return
        d = nodes.REGISTRY.get(node.kind)
        title = QLineEdit(node.label or (d.title if d else node.kind))
        title.setObjectName("inspectorTitle")
        title.setToolTip("Node label (shown on the canvas)")
        title.editingFinished.connect(lambda: self._rename(title.text()))
        head = QHBoxLayout()
        head.addWidget(title, 1)
        self.docs_button = QPushButton("Docs")
        self.docs_button.setToolTip("This node kind's documentation: ports, types, ranges (F1)")
        self.docs_button.clicked.connect(lambda _=False, k=node.kind: self.docsRequested.emit(k))
        head.addWidget(self.docs_button)
        lay.addLayout(head)
        kind = QLabel(f"{d.title if d else node.kind}  ·  {d.category if d else '?'}  ·  "
                      f"id {node.id}")
        kind.setObjectName("inspectorKind")
        lay.addWidget(kind)
        if d is not None:
            doc = QLabel(d.description)
            doc.setObjectName("inspectorDoc")
            doc.setWordWrap(True)
            lay.addWidget(doc)
        problems = [x for x in (self.controller.analysis.diagnostics
                                if self.controller.analysis else []) if x.node_id == node.id]
        for p in problems:
            msg = QLabel(f"{p.severity.value}: {p.format()}")
            msg.setWordWrap(True)
            msg.setStyleSheet("color: #e0605a;" if p.severity.value == "error"
                              else "color: #e5b94a;")
            lay.addWidget(msg)
        if d is not None:
            if role_of(node.kind) == Role.COLOR_RAMP:  # the stops editor (app/ramp_widget.py)
                from matedit.app.ramp_widget import RampEditor
                lay.addWidget(RampEditor(self.controller, node.id))
            self._build_settings(lay, node, d)
            self._build_values(lay, node, d)
            self._build_inputs(lay, node)
        lay.addStretch(1)
        self.setWidget(body)

    def _section(self, lay: QVBoxLayout, text: str) -> QFormLayout:
        header = QLabel(text)
        header.setObjectName("sectionHeader")
        lay.addWidget(header)
        form = QFormLayout()
        form.setLabelAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        form.setHorizontalSpacing(8)
        form.setVerticalSpacing(5)
        form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        lay.addLayout(form)
        return form

    @staticmethod
    def _label(text: str, tip: str = "") -> QLabel:
        lab = QLabel(text)
        lab.setObjectName("fieldLabel")
        if tip:
            lab.setToolTip(tip)
        return lab

    def _build_settings(self, lay, node: Node, d) -> None:
        # the canvas's pin groups are view state, toggled on the node itself
        shown = [s for s in d.settings if s.name not in ("layers", nodes.EXPANDED_GROUPS)]
        if role_of(node.kind) == Role.TEXTURE_PARAMETER:
            shown = [s for s in shown if s.name != "path"]
        if not shown and role_of(node.kind) not in (Role.TEXTURE_PARAMETER, Role.LAYER_STACK):
            return
        form = self._section(lay, "Settings")
        if role_of(node.kind) == Role.TEXTURE_PARAMETER:
            ref = str(node.settings.get("path", ""))
            f = TextureField(ref, absolute_of(self.controller.document, ref))
            f.edited.connect(lambda v, _m: self._set_texture(v))
            self._fields[("setting", "path")] = f
            form.addRow(self._label("image", "image file, relative to the material"), f)
        if role_of(node.kind) == Role.LAYER_STACK:
            n = len(node.settings.get("layers", []) or [])
            form.addRow(self._label("layers"),
                        QLabel(f"{n} layer{'s' if n != 1 else ''}: edit them in the Layers panel"))
        for s in shown:
            w = self._setting_editor(node, s)
            if w is not None:
                form.addRow(self._label(s.name, s.doc), w)

    def _setting_editor(self, node: Node, s: SettingDef) -> QWidget | None:
        cur = node.settings.get(s.name, s.default)
        if s.kind == "type" and s.choices:
            combo = guard_wheel(QComboBox())
            combo.addItems(list(s.choices))
            combo.setCurrentText(str(cur))
            combo.setToolTip(s.doc)
            combo.currentTextChanged.connect(lambda v, n=s.name: self._set_setting(n, v))
            return combo
        if s.kind == "bool":
            box = QCheckBox()
            box.setChecked(bool(cur))
            box.setToolTip(s.doc)
            box.toggled.connect(lambda v, n=s.name: self._set_setting(n, bool(v)))
            return box
        if s.kind == "number":
            spin = _spin()
            spin.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter)
            spin.setValue(float(cur or 0))
            spin.setToolTip(s.doc)
            as_int = isinstance(s.default, int)
            spin.valueChanged.connect(
                lambda v, n=s.name, i=as_int: self._set_setting(n, int(v) if i else float(v)))
            return spin
        if s.kind == "channels":
            edit = QLineEdit(str(cur))
            edit.setToolTip(s.doc)
            edit.setMaxLength(4)

            def commit(e=edit, n=s.name) -> None:
                try:
                    normalize_channels(e.text())
                except ValueError as exc:
                    self.message.emit(str(exc))
                    e.setText(str(self._node().settings.get(n, s.default)))
                    return
                self._set_setting(n, e.text())
            edit.editingFinished.connect(commit)
            return edit
        if s.kind == "path":
            return self._path_editor(node, s, str(cur or ""))
        if s.kind == "value":
            return self._value_setting_editor(node, s, cur)
        if s.kind == "list" and role_of(node.kind) == Role.SET_ATTRIBUTES:
            return self._fields_editor(node, cur)
        if s.kind == "string":
            edit = QLineEdit(str(cur))
            edit.setToolTip(s.doc)
            edit.editingFinished.connect(
                lambda e=edit, n=s.name: e.text() != str(self._node().settings.get(n, s.default))
                and self._set_setting(n, e.text()))
            return edit
        return None

    def _path_editor(self, node: Node, s: SettingDef, ref: str) -> QWidget:
        w = QWidget()
        row = QHBoxLayout(w)
        row.setContentsMargins(0, 0, 0, 0)
        edit = QLineEdit(ref)
        edit.setToolTip(s.doc)
        edit.editingFinished.connect(lambda: edit.text() != ref and
                                     self._set_setting(s.name, edit.text().strip()))
        browse = QPushButton("Browse…")
        browse.setToolTip("Choose a material function file")

        def pick() -> None:
            path, _ = file_dialogs.open_file(self, "Choose a material function", "",
                                             "Material functions (*.json)")
            if path:
                self._set_setting(s.name, reference_for(self.controller.document, path))
        browse.clicked.connect(pick)
        row.addWidget(edit, 1)
        row.addWidget(browse)
        if role_of(node.kind) == Role.FUNCTION_CALL and ref:
            open_btn = QPushButton("Open")
            open_btn.setToolTip("Open the function in a tab")
            target = absolute_of(self.controller.document, ref)
            open_btn.clicked.connect(lambda: self.functionOpenRequested.emit(str(target)))
            row.addWidget(open_btn)
        return w

    def _value_setting_editor(self, node: Node, s: SettingDef, cur) -> QWidget:
        t = str(node.settings.get("type", "float"))
        n = _COMPONENTS.get(t, 1)
        try:
            value = coerce_value(PortType(t), cur if cur is not None else 0.0)
        except ValueError:
            value = 0.0 if n == 1 else [0.0] * n
        return self._numeric_field(("setting", s.name), value, n, None, s.name, node.kind,
                                   lambda v, m, name=s.name: self._set_setting(name, v, m))

    def _fields_editor(self, node: Node, cur) -> QWidget:
        lst = QListWidget()
        lst.setMaximumHeight(8 + 20 * len(nodes.ATTRIBUTE_NAMES))
        chosen = set(cur or [])
        for name in nodes.ATTRIBUTE_NAMES:
            it = QListWidgetItem(name)
            it.setFlags(it.flags() | Qt.ItemFlag.ItemIsUserCheckable)
            it.setCheckState(Qt.CheckState.Checked if name in chosen else Qt.CheckState.Unchecked)
            lst.addItem(it)

        def changed(_item) -> None:
            picked = [lst.item(i).text() for i in range(lst.count())
                      if lst.item(i).checkState() == Qt.CheckState.Checked]
            self._set_setting("fields", picked)
        lst.itemChanged.connect(changed)
        return lst

    def _build_values(self, lay, node: Node, d) -> None:
        if not d.values:
            return
        form = self._section(lay, "Value")
        for v in d.values:
            cur = node.values.get(v.name, v.default)
            n = _COMPONENTS.get(v.type, 1)
            rng = v.range
            if role_of(node.kind) == Role.SCALAR_PARAMETER:
                lo = node.settings.get("ui_min", 0.0)
                hi = node.settings.get("ui_max", 1.0)
                if isinstance(lo, (int, float)) and isinstance(hi, (int, float)) and hi > lo:
                    rng = (float(lo), float(hi))
            try:
                value = coerce_value(PortType(v.type), cur)
            except ValueError:
                value = coerce_value(PortType(v.type), v.default)
            w = self._numeric_field(("value", v.name), value, n, rng, v.name, node.kind,
                                    lambda val, m, p=v.name: self._set_value(p, val, m))
            form.addRow(self._label(v.name, v.doc), w)

    def _build_inputs(self, lay, node: Node) -> None:
        a = self.controller.analysis
        ports = a.ports.get(node.id) if a else None
        if ports is None or not ports.inputs:
            return
        connected = self.controller.document.graph.inputs_of(node.id)
        in_types = (a.in_types.get(node.id) or {}) if a else {}
        groups: list[tuple[str, list[Port]]] = []
        layer_names = {}
        if role_of(node.kind) == Role.LAYER_STACK:
            for e in node.settings.get("layers", []) or []:
                if isinstance(e, dict) and isinstance(e.get("id"), str):
                    layer_names[e["id"]] = str(e.get("name") or e["id"])
        for p in ports.inputs:
            group = nodes.port_group(node.kind, p.name) or "Inputs"
            if layer_names:
                lid = next((lid for lid in sorted(layer_names, key=len, reverse=True)
                            if p.name.startswith(lid + "_")), None)
                if lid is not None:
                    group = f"Layer: {layer_names[lid]}"
            if not groups or groups[-1][0] != group:
                groups.append((group, []))
            groups[-1][1].append(p)
        for group, specs in groups:
            form = None
            for p in specs:
                if form is None:
                    form = self._section(lay, group)
                label_text = p.name
                if role_of(node.kind) == Role.LAYER_STACK:
                    lid = next((k for k in layer_names if p.name.startswith(k + "_")), None)
                    if lid:
                        label_text = p.name[len(lid) + 1:]
                if p.type == "texture2d" and self._texture_slot(form, node, p, label_text):
                    continue
                if p.name in connected:
                    src = connected[p.name]
                    form.addRow(self._label(label_text, p.doc),
                                QLabel(f"← {src.src}.{src.src_port}"))
                    continue
                t = in_types.get(p.name)
                tname = t.value if t is not None else p.type
                if tname not in _COMPONENTS:
                    if p.required:
                        form.addRow(self._label(label_text, p.doc),
                                    self._hint(f"connect a {tname}"))
                    continue
                cur = node.values.get(p.name, p.default)
                if cur == MESH_UV or (cur is None and tname == "vec2"):
                    if p.name not in node.values:
                        form.addRow(self._label(label_text, p.doc), self._hint("mesh UVs"))
                        continue
                try:
                    value = coerce_value(PortType(tname), cur if cur is not None else 0.0)
                except ValueError:
                    value = 0.0 if tname == "float" else [0.0] * _COMPONENTS[tname]
                w = self._numeric_field(("value", p.name), value, _COMPONENTS[tname], p.range,
                                        p.name, node.kind,
                                        lambda val, m, port=p.name: self._set_value(port, val, m))
                form.addRow(self._label(label_text, p.doc), w)

    def _texture_slot(self, form, node: Node, p: Port, label: str) -> bool:
        """A texture input's file field: the image of the Texture Parameter wired in, or
        none yet (choosing one makes the parameter, `textureSlotChosen`). False when the
        input is fed by something else (its source is shown instead)."""
        graph = self.controller.document.graph
        link = graph.incoming(node.id, p.name)
        ref = ""
        if link is not None:
            src = graph.nodes.get(link.src)
            if src is None or role_of(src.kind) != Role.TEXTURE_PARAMETER:
                return False
            ref = str(src.settings.get("path", ""))
        f = TextureField(ref, absolute_of(self.controller.document, ref) if ref else None)
        f.setToolTip(f"the image {link.src} reads" if link is not None else
                     "choose an image: a Texture Parameter on it is made and wired in")
        f.edited.connect(lambda v, _m, n=node.id, port=p.name:
                         self.textureSlotChosen.emit(n, port, str(v or "")))
        self._fields[("slot", p.name)] = f
        form.addRow(self._label(label, p.doc), f)
        return True

    @staticmethod
    def _hint(text: str) -> QLabel:
        lab = QLabel(text)
        lab.setObjectName("emptyHint")
        return lab

    def _numeric_field(self, key, value, n: int, rng, name: str, kind: str, on_edit) -> QWidget:
        if n == 1:
            f = FloatField(float(value), rng)
        elif n == 3 and is_colour(name, kind):
            f = ColorField(list(value))
        else:
            f = VectorField(list(value))
        f.edited.connect(on_edit)
        self._fields[key] = f
        return f

    # --- refreshing ------------------------------------------------------------------------
    def refresh_values(self) -> None:
        """Show the model's current numbers (after an undo, or an edit from another panel)."""
        node = self._node()
        if node is None:
            return
        d = nodes.REGISTRY.get(node.kind)
        a = self.controller.analysis
        ports = a.ports.get(node.id) if a else None
        for (where, name), f in self._fields.items():
            if where == "slot":  # the image of the parameter wired in (a value edit there)
                link = self.controller.document.graph.incoming(node.id, name)
                src = self.controller.document.graph.nodes.get(link.src) if link else None
                ref = str(src.settings.get("path", "")) if src is not None else ""
                f.set_value(ref, absolute_of(self.controller.document, ref) if ref else None)
                continue
            if where == "setting":
                if isinstance(f, TextureField):
                    ref = str(node.settings.get("path", ""))
                    f.set_value(ref, absolute_of(self.controller.document, ref))
                continue
            spec = next((v for v in (d.values if d else ()) if v.name == name), None)
            default = spec.default if spec else None
            if spec is None and ports is not None:
                p = ports.input(name)
                default = p.default if p else None
            cur = node.values.get(name, default)
            if cur is None or cur == MESH_UV:
                continue
            try:
                if isinstance(f, FloatField):
                    f.set_value(float(coerce_value(PortType.FLOAT, cur)))
                else:
                    n = 3 if isinstance(f, ColorField) else len(f.spins)
                    f.set_value(coerce_value(PortType({2: "vec2", 3: "vec3", 4: "vec4"}[n]),
                                             cur))
            except (ValueError, TypeError):
                continue

    # --- edits -----------------------------------------------------------------------------
    def _set_value(self, port: str, value, merge_id: int | None = None) -> None:
        node = self._node()
        if node is None:
            return
        a = self.controller.analysis
        spec = a.ports[node.id].input(port) if a and node.id in a.ports else None
        problem = limit_problem(spec, value) if spec is not None else None
        if problem is not None:  # clamped, and said: the field shows the bound it took
            why, value = problem
            self.message.emit(f"{node.id}: {why}; set to {_shown(value)}")
            QTimer.singleShot(0, self.refresh_values)
        if node.values.get(port) == value:
            return
        self.controller.push(SetValue(node.id, port, value, text=f"set {node.id}.{port}"),
                             merge_id=merge_id)

    def _set_setting(self, name: str, value, merge_id: int | None = None) -> bool:
        node = self._node()
        if node is None or node.settings.get(name) == value:
            return False
        return self.controller.push(
            SetSetting(node.id, name, value, text=f"set {node.id} {name}"), merge_id=merge_id)

    def _set_texture(self, path: str) -> None:
        ref = reference_for(self.controller.document, path) if path else ""
        self._set_setting("path", ref)

    def _rename(self, text: str) -> None:
        node = self._node()
        if node is None:
            return
        d = nodes.REGISTRY.get(node.kind)
        label = "" if d is not None and text == d.title else text.strip()
        if label != node.label:
            self.controller.push(SetLabel(node.id, label))
