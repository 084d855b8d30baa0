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


_TENSOR_TYPE = None


def tensor_rows(values) -> pa.Array:
    """One rerun TensorData (1-D, float32) per row of `values` (n, k), or per array of a list of
    1-D arrays (rows of different lengths), built as one arrow array (rerun's own
    `BarChart.columns` takes one tensor for all rows)."""
    global _TENSOR_TYPE
    if _TENSOR_TYPE is None:
        _TENSOR_TYPE = (
            rr.components.TensorDataBatch(rr.encodings.TensorData(array=np.zeros(1, np.float32))).as_arrow_array().type
        )
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
    f_shape, f_names, f_buffer = _TENSOR_TYPE[0], _TENSOR_TYPE[1], _TENSOR_TYPE[2]
    shape = pa.ListArray.from_arrays(
        pa.array(np.arange(n + 1, dtype=np.int32)), pa.array(sizes.astype(np.uint64)), type=f_shape.type
    )
    utype = f_buffer.type
    children = []
    code = None
    for i in range(utype.num_fields):
        ft = utype.field(i)
        if ft.name == "F32":
            code = utype.type_codes[i]
            children.append(pa.ListArray.from_arrays(pa.array(offsets), pa.array(values.reshape(-1)), type=ft.type))
        else:
            children.append(pa.array([], type=ft.type))
    buffer = pa.Array.from_buffers(
        utype,
        n,
        [
            None,
            pa.py_buffer(np.full(n, code, dtype=np.int8).tobytes()),
            pa.py_buffer(np.arange(n, dtype=np.int32).tobytes()),
        ],
        children=children,
    )
    return pa.StructArray.from_arrays(
        [shape, pa.nulls(n, type=f_names.type), buffer], fields=[f_shape, f_names, f_buffer]
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
