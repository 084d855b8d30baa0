"""Ready arrow arrays for rerun's columnar API: a component column from an arrow array, rows of
1-D float32 tensors built as one arrow array, and bar-chart columns (values, abscissa, widths)."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import rerun as rr


class ArrowColumn:
    """A ready arrow array as a `ComponentBatchLike`."""

    def __init__(self, array: pa.Array) -> None:
        self.array = array

    def as_arrow_array(self) -> pa.Array:
        return self.array


class _TensorLayout:
    """The arrow pieces of rerun's TensorData that do not depend on the values, made once: the
    struct's fields, the buffer union's type with its F32 member, and an empty array for every
    other member of the union (arrow arrays are immutable, so one set serves every call)."""

    def __init__(self) -> None:
        tensor_type = (
            rr.components.TensorDataBatch(rr.encodings.TensorData(array=np.zeros(1, np.float32))).as_arrow_array().type
        )
        self.shape_field, self.names_field, self.buffer_field = tensor_type[0], tensor_type[1], tensor_type[2]
        union = self.buffer_field.type
        self.union = union
        self.f32_member = next(i for i in range(union.num_fields) if union.field(i).name == "F32")
        self.f32_code = union.type_codes[self.f32_member]
        self.f32_type = union.field(self.f32_member).type
        self.empty_members = [pa.array([], type=union.field(i).type) for i in range(union.num_fields)]


_LAYOUT: _TensorLayout | None = None


def tensor_rows(values) -> pa.Array:
    """One rerun TensorData (1-D, float32) per row of `values` (n, k), or per array of a list of
    1-D arrays (rows of different lengths), built as one arrow array (rerun's own
    `BarChart.columns` takes one tensor for all rows)."""
    global _LAYOUT
    layout = _LAYOUT
    if layout is None:
        layout = _LAYOUT = _TensorLayout()
    if isinstance(values, np.ndarray):
        values = np.ascontiguousarray(values, dtype=np.float32)
        n, k = values.shape
        sizes = np.full(n, k, dtype=np.int64)
    else:
        sizes = np.array([len(v) for v in values], dtype=np.int64)
        n = sizes.size
        values = np.concatenate([np.asarray(v, dtype=np.float32) for v in values]) if n else np.zeros(0, np.float32)
    offsets = np.zeros(n + 1, dtype=np.int32)
    np.cumsum(sizes, out=offsets[1:])
    shape = pa.ListArray.from_arrays(
        pa.array(np.arange(n + 1, dtype=np.int32)), pa.array(sizes.astype(np.uint64)), type=layout.shape_field.type
    )
    children = list(layout.empty_members)
    children[layout.f32_member] = pa.ListArray.from_arrays(
        pa.array(offsets), pa.array(values.reshape(-1)), type=layout.f32_type
    )
    buffer = pa.Array.from_buffers(
        layout.union,
        n,
        [
            None,
            pa.py_buffer(np.full(n, layout.f32_code, dtype=np.int8).tobytes()),
            pa.py_buffer(np.arange(n, dtype=np.int32).tobytes()),
        ],
        children=children,
    )
    return pa.StructArray.from_arrays(
        [shape, pa.nulls(n, type=layout.names_field.type), buffer],
        fields=[layout.shape_field, layout.names_field, layout.buffer_field],
    )


def bar_columns(values, abscissa, widths=None) -> list:
    """BarChart columns, a row per row of values / abscissa (arrays (n, k) or lists of 1-D
    arrays); widths: the bar widths of each row (a list of 1-D arrays), else the static ones."""
    out = [
        rr.ComponentColumn(rr.BarChart.descriptor_values(), ArrowColumn(tensor_rows(values))),
        rr.ComponentColumn(rr.BarChart.descriptor_abscissa(), ArrowColumn(tensor_rows(abscissa))),
    ]
    if widths is not None:
        out.append(
            rr.ComponentColumn(
                rr.BarChart.descriptor_widths(),
                rr.components.LengthBatch(np.concatenate(widths).astype(np.float32)),
                lengths=np.array([len(w) for w in widths]),
            )
        )
    return out
