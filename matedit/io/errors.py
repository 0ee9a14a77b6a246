"""The error of a file that cannot be read as a matedit document: raised by the loader
(`matedit.io.document`, which exports it) and by the shape check (`matedit.io.schema`)."""

from __future__ import annotations


class FormatError(ValueError):
    """A file that cannot be read as a matedit document."""

    def __init__(self, file: str | None, message: str, node: str | None = None,
                 field: str | None = None) -> None:
        self.file, self.node, self.field, self.reason = file, node, field, message
        where = []
        if node:
            where.append(f"node {node}")
        if field:
            where.append(f"field {field}")
        loc = (", ".join(where) + ": ") if where else ""
        super().__init__(f"{file or '<document>'}: {loc}{message}")
