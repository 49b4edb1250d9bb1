"""Write the BinaryCIF fixtures of crates/md-io/tests/mmcif.rs from the PDBx/mmCIF fixtures of
tests/data, with two independent writers, and what a third-party decoder reads back from each.

Run from this directory: `MOLSTAR=/tmp/mol/node_modules python3 gen_bcif.py`, $MOLSTAR the
node_modules directory of `npm install --prefix /tmp/mol molstar@5.6.1` (outside the repository).

Versions: biotite 1.6.0 (numpy 2.4.6, msgpack 1.2.4), Mol* 5.6.1 on Node 20.

Writers
- biotite (`biotite_*.bcif`): each source file's categories _entry, _cell, _symmetry, _struct
  and _atom_site copied column by column into a `BinaryCIFFile`, each column typed as int when
  every present value is a canonical integer, as float when every one is a plain decimal, else
  string, and the '.'/'?' of the text as the column's mask:
  - `biotite_<name>.bcif`: then `biotite.structure.io.pdbx.compress` (the smallest of
    biotite's encodings per column: FixedPoint, Delta, RunLength, IntegerPacking, StringArray);
  - `biotite_gemmi_topo_plain.bcif`: uncompressed (ByteArray Int32 / Float64 columns,
    StringArray with ByteArray indices and offsets);
  - `biotite_gemmi_multi_encodings.bcif`: encodings chosen by hand so that every kind the
    format has is met in a real file: ByteArray of each type, Float32 and Float64 FixedPoint,
    IntervalQuantization (Cartn_z: 2^16 steps over the column's range; biotite takes the
    step at or above a value, so a coordinate is within a step of the text's), RunLength,
    Delta, IntegerPacking signed and unsigned of 1 and 2 bytes.
- Mol* (`molstar_*.bcif`): `cif2bcif` of Mol*'s command line, with a filter keeping the same
  five categories (its own encodings: FixedPoint from the decimals, Delta, RunLength,
  IntegerPacking, StringArray with Delta-coded offsets); `molstar_3jqh.bcif.gz` the same,
  gzipped by cif2bcif.

bcif_reference.json holds biotite's decoding of every .bcif here (its `BinaryCIFFile`, not
its structure parser): per file the _atom_site row count, the model number and atom name
(auth_atom_id, else label_atom_id) of every row, the first and last rows' coordinates as
decoded (float64, or the float32 of a Float32 column, written exactly), the cell and the title.
"""
import gzip
import json
import os
import re
import subprocess

import biotite
import msgpack
import numpy as np
import biotite.structure.io.pdbx as pdbx
from biotite.structure.io.pdbx import (
    ByteArrayEncoding, DeltaEncoding, FixedPointEncoding, IntegerPackingEncoding,
    IntervalQuantizationEncoding, RunLengthEncoding, StringArrayEncoding, TypeCode,
)

assert biotite.__version__ == "1.6.0", biotite.__version__

DATA = ".."
KEEP = ["entry", "cell", "symmetry", "struct", "atom_site"]
SOURCES = ["gemmi_multi", "3jqh", "1uqc"]

INT = re.compile(r"-?(0|[1-9][0-9]*)$")
DECIMAL = re.compile(r"-?[0-9]+\.[0-9]*$")


def typed(col):
    """A CIF column's values as an int32, float64 or str array, and its mask (None if none)."""
    values = col.as_array(str)
    mask = None if col.mask is None else col.mask.array.astype(np.uint8)
    present = values if mask is None else values[mask == 0]
    if all(INT.match(v) for v in present):
        dtype = np.int32
    elif len(present) and all(INT.match(v) or DECIMAL.match(v) for v in present):
        dtype = np.float64
    else:
        out = values.copy()
        if mask is not None:
            out[mask != 0] = ""
        return out, mask
    out = np.zeros(len(values), dtype=dtype)
    keep = slice(None) if mask is None else mask == 0
    out[keep] = [dtype(v) for v in present]
    return out, mask


def to_bcif(name, encode=None):
    """The BinaryCIF file of tests/data/<name>.cif; `encode(category, column, array)` may give
    a column's encodings."""
    cif = pdbx.CIFFile.read(f"{DATA}/{name}.cif")
    out = pdbx.BinaryCIFFile()
    for block_name, block in cif.items():
        b = pdbx.BinaryCIFBlock()
        for cat_name in KEEP:
            if cat_name not in block:
                continue
            columns = {}
            for col_name, col in block[cat_name].items():
                array, mask = typed(col)
                encoding = None
                chosen = encode(cat_name, col_name, array) if encode else None
                if chosen is not None:
                    encoding, array = chosen
                columns[col_name] = pdbx.BinaryCIFColumn(
                    pdbx.BinaryCIFData(array, encoding),
                    None if mask is None else pdbx.BinaryCIFData(mask),
                )
            b[cat_name] = pdbx.BinaryCIFCategory(columns)
        out[block_name] = b
    return out


def by_hand(cat, col, array):
    """Every encoding of the format, on gemmi_multi's columns: (encodings, array) or None."""
    if cat != "atom_site":
        return None
    packed = lambda count, unsigned, t: [IntegerPackingEncoding(count, is_unsigned=unsigned),
                                         ByteArrayEncoding(t)]
    strings = lambda data: [StringArrayEncoding(
        data_encoding=data, offset_encoding=[DeltaEncoding(), *packed(1, True, TypeCode.UINT8)])]
    real = array.astype(np.float64) if array.dtype.kind in "if" else None
    if col == "Cartn_x":
        return [ByteArrayEncoding(TypeCode.FLOAT64)], real
    if col == "Cartn_y":
        return [FixedPointEncoding(1000, TypeCode.FLOAT32), DeltaEncoding(),
                *packed(2, False, TypeCode.INT16)], real
    if col == "Cartn_z":
        iq = IntervalQuantizationEncoding(float(real.min()), float(real.max()), 65536,
                                          TypeCode.FLOAT64)
        return [iq, *packed(2, True, TypeCode.UINT16)], real
    if col == "occupancy":
        # 1000 per value: chains of the signed 1-byte limit 127.
        return [FixedPointEncoding(1000, TypeCode.FLOAT32), *packed(1, False, TypeCode.INT8)], real
    if col == "B_iso_or_equiv":
        return [ByteArrayEncoding(TypeCode.FLOAT32)], real.astype(np.float32)
    table = {
        "id": [DeltaEncoding(), RunLengthEncoding(), *packed(1, True, TypeCode.UINT8)],
        "auth_seq_id": [ByteArrayEncoding(TypeCode.INT16)],
        "label_seq_id": [ByteArrayEncoding(TypeCode.UINT16)],
        "pdbx_PDB_model_num": [RunLengthEncoding(), ByteArrayEncoding(TypeCode.UINT32)],
        "pdbx_formal_charge": [ByteArrayEncoding(TypeCode.INT8)],
        "label_atom_id": strings([*packed(2, False, TypeCode.INT16)]),
        "label_comp_id": strings([ByteArrayEncoding(TypeCode.UINT16)]),
        "label_asym_id": strings([ByteArrayEncoding(TypeCode.UINT32)]),
        "type_symbol": strings([RunLengthEncoding(), ByteArrayEncoding(TypeCode.INT32)]),
        "auth_asym_id": strings([DeltaEncoding(), RunLengthEncoding(),
                                 *packed(1, False, TypeCode.INT8)]),
    }
    return (table[col], array) if col in table else None


def write_biotite():
    for name in SOURCES:
        pdbx.compress(to_bcif(name)).write(f"biotite_{name}.bcif")
    to_bcif("gemmi_topo").write("biotite_gemmi_topo_plain.bcif")
    to_bcif("gemmi_multi", by_hand).write("biotite_gemmi_multi_encodings.bcif")


def write_molstar():
    root = os.environ.get("MOLSTAR", "node_modules")
    cli = f"{root}/molstar/lib/commonjs/cli/cif2bcif/index.js"
    with open("molstar_filter.txt", "w") as f:
        f.write("\n".join(KEEP) + "\n")
    try:
        for name in SOURCES:
            subprocess.run(["node", cli, f"{DATA}/{name}.cif", f"molstar_{name}.bcif",
                            "-f", "molstar_filter.txt"], check=True, stdout=subprocess.DEVNULL)
        subprocess.run(["node", cli, f"{DATA}/3jqh.cif", "molstar_3jqh.bcif.gz",
                        "-f", "molstar_filter.txt"], check=True, stdout=subprocess.DEVNULL)
    finally:
        os.remove("molstar_filter.txt")


def column(cat, name):
    return cat[name] if name in cat else None


def reference(path):
    bcif = pdbx.BinaryCIFFile.read(path)
    block = bcif.block
    atoms = block["atom_site"]
    xyz = [atoms[f"Cartn_{c}"].data.array for c in "xyz"]
    name = "auth_atom_id" if "auth_atom_id" in atoms else "label_atom_id"
    names = atoms[name].data.array
    models = atoms["pdbx_PDB_model_num"].data.array
    out = {
        "encoder": msgpack.unpackb(open_bytes(path), raw=False)["encoder"],
        "rows": atoms.row_count,
        "models": [int(m) for m in models],
        "names": [str(n) for n in names],
        "first": [float(a[0]) for a in xyz],
        "last": [float(a[-1]) for a in xyz],
        "cell": None,
        "title": None,
    }
    if "cell" in block:
        cell = block["cell"]
        out["cell"] = [float(cell[k].data.array[0]) for k in
                       ["length_a", "length_b", "length_c", "angle_alpha", "angle_beta", "angle_gamma"]]
    if "struct" in block:
        out["title"] = str(block["struct"]["title"].data.array[0])
    return out


def open_bytes(path):
    with open(path, "rb") as f:
        b = f.read()
    return gzip.decompress(b) if path.endswith(".gz") else b


if __name__ == "__main__":
    write_biotite()
    write_molstar()
    files = sorted(f for f in os.listdir(".") if f.endswith(".bcif"))
    ref = {}
    for f in files:
        ref[f] = reference(f)
    with open("bcif_reference.json", "w") as f:
        json.dump({"biotite": biotite.__version__, "files": ref}, f, indent=1)
        f.write("\n")
