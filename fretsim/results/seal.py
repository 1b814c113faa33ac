"""Checksums: every dataset and every group's attributes carry a sha256 of what was written (format 1.3 on), and
the writer that seals a file as it writes it; the checkpoint carries its own digest."""
from __future__ import annotations

import hashlib
from typing import Optional

import h5py
import numpy as np

from fretsim.errors import ResultsFileError
from fretsim.results.layout import MAX_DATASET_BYTES



class _Damaged(ResultsFileError):
    pass


# --- the whole file: its bytes' sha256 in an HDF5 user block (which HDF5 skips), checked before HDF5 reads a byte.
# libhdf5 loops for ever on some damaged files (a flipped bit in the size of a global-heap object, HDFGroup/hdf5
# #1707), so a file must be known intact before it is handed to it; the per-object seals then name what an edit
# that also rewrote this digest changed.
USERBLOCK = 512
IMAGE_MAGIC = b"fretsim results file; sha256 of the bytes from 512 on: "
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_CHUNK = 1 << 20


def seal_image(data: bytes) -> bytes:
    """An HDF5 image written with a USERBLOCK-byte user block, with the digest of the rest written into it."""
    digest = hashlib.sha256(memoryview(data)[USERBLOCK:]).hexdigest().encode()
    head = (IMAGE_MAGIC + digest + b"\n").ljust(USERBLOCK, b"\0")
    return b"".join((head, memoryview(data)[USERBLOCK:]))  # one copy of the image, not two


def verify_image(path) -> bool:
    """Refuse (``_Damaged``) a file whose bytes differ from the digest in its user block; a file without a user
    block (written before it was added) is left to the per-object seals.  True where the digest was there and
    matched: every byte is as written."""
    with open(path, "rb") as fh:
        head = fh.read(USERBLOCK)
        if head[:8] == HDF5_SIGNATURE:
            return False
        first = fh.read(8)
        if first != HDF5_SIGNATURE:
            return False  # not HDF5 where fretsim puts it: HDF5's own reading says what it is
        if not head.startswith(IMAGE_MAGIC) or head[len(IMAGE_MAGIC) + 64:len(IMAGE_MAGIC) + 65] != b"\n":
            raise _Damaged("its header block (the first 512 bytes, which hold the file's checksum) is damaged")
        expected = head[len(IMAGE_MAGIC):len(IMAGE_MAGIC) + 64].decode("ascii", "replace")
        h = hashlib.sha256(first)
        for chunk in iter(lambda: fh.read(_CHUNK), b""):
            h.update(chunk)
    if h.hexdigest() != expected:
        raise _Damaged("its bytes do not match the checksum written with them (changed since it was written: an "
                       "edit, a flipped bit, a truncated copy)")
    return True


def reseal_file(path) -> None:
    """Write a file's whole-file digest again (for a tool that edits a results file on purpose and re-seals its
    objects with :func:`_seal`)."""
    with open(path, "rb") as fh:
        data = fh.read()
    if data[USERBLOCK:USERBLOCK + 8] == HDF5_SIGNATURE:
        with open(path, "wb") as fh:
            fh.write(seal_image(data))


def text(value) -> str:
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.ndarray) and value.shape == ():
        return text(value[()])
    return str(value)


# --- checksums: every dataset and every group's attributes carry a sha256 of what was written ----------------------
SEALED_FROM = "1.3"  # files of this format on carry (and must carry) the checksums
_SCALE_ATTRS = {"DIMENSION_LIST", "REFERENCE_LIST", "CLASS", "NAME", "sha256", "attrs_sha256"}  # HDF5's own, ours


def _value_digest(value) -> str:
    """sha256 of a dataset's value as read back: a text by its UTF-8 bytes (so /case's is the sha256 of its YAML,
    as it always was), an array by its type, shape and bytes."""
    if isinstance(value, bytes):
        return hashlib.sha256(value).hexdigest()
    if isinstance(value, str):
        return hashlib.sha256(value.encode()).hexdigest()
    a = np.asarray(value)
    h = hashlib.sha256(f"{a.dtype.str}{a.shape}".encode())
    if a.dtype.kind == "O":
        for v in a.ravel():
            h.update(v if isinstance(v, bytes) else str(v).encode())
            h.update(b"\0")
    else:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _attrs_digest(obj) -> str:
    """sha256 of an object's attributes and, for a group, of the names it holds (so a deleted or added dataset
    shows)."""
    h = hashlib.sha256()
    if isinstance(obj, h5py.Group):
        h.update(("members:" + "\0".join(sorted(obj.keys())) + "\0").encode())
    for k in sorted(k for k in obj.attrs.keys() if k not in _SCALE_ATTRS):
        v = obj.attrs[k]
        h.update(k.encode() + b"=")
        h.update(v if isinstance(v, bytes) else _value_digest(v).encode() if isinstance(v, np.ndarray) else
                 repr(v).encode())
        h.update(b"\0")
    return h.hexdigest()


def _sealed_objects(f):
    """Every group (the root included) and dataset the readers trust; /checkpoint carries its own digest."""
    out = [("", f)]
    f.visititems(lambda name, obj: None if name == "checkpoint" or name.startswith("checkpoint/") else
                 out.append((name, obj)))
    return out


def _seal(f) -> None:
    for name, obj in _sealed_objects(f):
        if isinstance(obj, h5py.Dataset):
            obj.attrs["sha256"] = _value_digest(obj[()])
        obj.attrs["attrs_sha256"] = _attrs_digest(obj)


def _verify_seal(f) -> None:
    """Refuse a file whose datasets or attributes differ from what was written, naming the first that does."""
    for name, obj in _sealed_objects(f):
        where = f"/{name}"
        if isinstance(obj, h5py.Dataset):
            if "sha256" not in obj.attrs:
                raise _Damaged(f"{where}: its checksum is missing (every dataset of this format carries one)")
            if obj.size * max(obj.dtype.itemsize, 1) > MAX_DATASET_BYTES:
                raise _Damaged(f"{where}: declares {obj.size:.3g} values, more than any results file holds")
            if _value_digest(obj[()]) != text(obj.attrs["sha256"]):
                raise _Damaged(f"{where}: its values do not match their checksum (changed since it was written)")
        if "attrs_sha256" not in obj.attrs:
            raise _Damaged(f"{where or '/'}: the checksum of its attributes is missing")
        if _attrs_digest(obj) != text(obj.attrs["attrs_sha256"]):
            raise _Damaged(f"{where or '/'}: its attributes{'' if isinstance(obj, h5py.Dataset) else ' or the names it holds'}"
                           f" do not match their checksum (changed since it was written)")


def _verify_attrs_seal(f, names: tuple) -> None:
    """Refuse a file where the attributes (and member names) of the groups ``names`` ("" the root) differ from
    their checksums: cheap, no dataset is read (what a reader that trusts the whole-file checksum for the rest
    still checks of what it reports)."""
    for name in names:
        obj = f[name] if name else f
        where = f"/{name}"
        if "attrs_sha256" not in obj.attrs:
            raise _Damaged(f"{where}: the checksum of its attributes is missing")
        if _attrs_digest(obj) != text(obj.attrs["attrs_sha256"]):
            raise _Damaged(f"{where}: its attributes or the names it holds do not match their checksum (changed "
                           f"since it was written)")


class _SealingWriter:
    """Creates the sealed groups and datasets of a file and seals them from the values it was given, without
    reading the file back (which cost most of a flush).  Each value is taken in the form HDF5 gives it back (a
    Python float as numpy.float64, a text list as bytes), so the seal is the one :func:`_seal` would compute and
    :func:`_verify_seal` checks; an object created past this writer is left unsealed and the reader refuses it."""

    def __init__(self, f: h5py.File):
        self._objects = {"/": f}
        self._attrs = {"/": {}}
        self._members = {"/": []}
        self._digests = {}

    def group(self, parent, name: str, **attrs):
        g = parent.create_group(name)
        self._enter(parent, g, name)
        self.attrs(g, **attrs)
        return g

    def dataset(self, parent, name: str, data, dtype=None, **attrs):
        ds = _new_dataset(parent, name, data, dtype)
        self._enter(parent, ds, name)
        try:
            self._digests[ds.name] = _given_digest(data, dtype)
        except TypeError:  # a value of another kind: sealed as it reads back
            self._digests[ds.name] = _value_digest(ds[()])
        self.attrs(ds, **attrs)
        return ds

    def attrs(self, obj, **attrs) -> None:
        given = self._attrs[obj.name]
        for key, value in attrs.items():
            if given is not None and key in given or given is None and key in obj.attrs:
                del obj.attrs[key]
            _new_attr(obj, key, value)
            if given is not None:
                try:
                    given[key] = _as_read(value)
                except TypeError:  # a value of another kind: this object's attributes are sealed as they read back
                    self._attrs[obj.name] = given = None

    def unsealed_group(self, parent, name: str):
        self._members[parent.name].append(name)
        return parent.create_group(name)

    def seal(self) -> None:
        for name, obj in self._objects.items():
            if name in self._digests:
                _new_attr(obj, "sha256", self._digests[name])
            given = self._attrs[name]
            _new_attr(obj, "attrs_sha256", _attrs_digest(obj) if given is None else
                      _digest_of_attrs(given, self._members.get(name)))

    def _enter(self, parent, obj, name: str) -> None:
        self._objects[obj.name] = obj
        self._attrs[obj.name] = {}
        self._members[parent.name].append(name)
        if isinstance(obj, h5py.Group):
            self._members[obj.name] = []


_TEXT = h5py.string_dtype()
_HTYPES: dict = {}


def _types(key) -> tuple:
    """The HDF5 file and memory types h5py makes for a numpy dtype (or "text": variable-length UTF-8), made once."""
    if key not in _HTYPES:
        dtype = _TEXT if key == "text" else key
        _HTYPES[key] = (h5py.h5t.py_create(dtype, logical=True), h5py.h5t.py_create(dtype))
    return _HTYPES[key]


def _space(shape: tuple):
    if shape:
        return h5py.h5s.create_simple(shape)
    if "scalar" not in _HTYPES:
        _HTYPES["scalar"] = h5py.h5s.create(h5py.h5s.SCALAR)
    return _HTYPES["scalar"]


def _new_attr(obj, name: str, value) -> None:
    """obj.attrs[name] = value for a name not yet there, by HDF5's own calls: the same attribute h5py writes
    (a text as variable-length UTF-8, a number or numeric array by its numpy type) at a third of the cost."""
    if isinstance(value, str):
        data, key = np.array(value, dtype=_TEXT), "text"
    else:
        data = np.asarray(value)
        key = data.dtype
        if data.dtype.kind not in "biuf":
            obj.attrs[name] = value
            return
    logical, memory = _types(key)
    attr = h5py.h5a.create(obj.id, name.encode(), logical, _space(data.shape))
    try:
        attr.write(data, mtype=memory)
    finally:
        attr.close()


def _new_dataset(parent, name: str, data, dtype=None):
    """parent.create_dataset(name, data=data, dtype=dtype) by HDF5's own calls for the contiguous text and
    numeric datasets of this layout (h5py's general path cost half a flush); anything else goes through h5py."""
    if isinstance(data, str) or (dtype is not None and h5py.check_string_dtype(dtype) is not None):
        array, key = np.array(data, dtype=_TEXT), "text"
    else:
        array = np.asarray(data, dtype=dtype)
        key = array.dtype
        if array.dtype.kind not in "biuf":
            return parent.create_dataset(name, data=data, dtype=dtype)
    logical, memory = _types(key)
    space = _space(array.shape)
    if "dcpl" not in _HTYPES:  # as h5py's: no creation and modification times, so equal runs write equal bytes
        _HTYPES["dcpl"] = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
        _HTYPES["dcpl"].set_obj_track_times(False)
    dset = h5py.h5d.create(parent.id, name.encode(), logical, space, dcpl=_HTYPES["dcpl"])
    if array.size:
        dset.write(h5py.h5s.ALL, h5py.h5s.ALL, np.ascontiguousarray(array), mtype=memory)
    return h5py.Dataset(dset)


def _as_read(value):
    """An attribute's value as h5py reads it back."""
    if isinstance(value, str):
        return str(value)
    if isinstance(value, (bool, np.bool_)):
        return np.bool_(value)
    if isinstance(value, int):
        return np.int64(value)
    if isinstance(value, float):
        return np.float64(value)
    if isinstance(value, np.ndarray):
        return value[()] if value.ndim == 0 else value  # h5py gives a 0-d array back as its scalar
    if isinstance(value, np.number):
        return value
    raise TypeError(f"an attribute of type {type(value).__name__} is not sealed by value")


def _given_digest(data, dtype) -> str:
    """_value_digest of a dataset's value as read back, from the value it was created with."""
    if isinstance(data, str):
        return _value_digest(data)
    if dtype is not None and h5py.check_string_dtype(dtype) is not None:
        return _value_digest(np.array([v.encode() for v in data], dtype=object).reshape(len(data)))
    a = np.asarray(data, dtype=dtype)
    if a.dtype.kind in "OUS":
        raise TypeError("text datasets are written with a string dtype")
    return _value_digest(a)


def _digest_of_attrs(attrs: dict, members: Optional[list]) -> str:
    """_attrs_digest of an object from the attributes given to it (as read back) and, for a group, its members."""
    h = hashlib.sha256()
    if members is not None:
        h.update(("members:" + "\0".join(sorted(members)) + "\0").encode())
    for k in sorted(k for k in attrs if k not in _SCALE_ATTRS):
        v = attrs[k]
        h.update(k.encode() + b"=")
        h.update(v if isinstance(v, bytes) else _value_digest(v).encode() if isinstance(v, np.ndarray) else
                 repr(v).encode())
        h.update(b"\0")
    return h.hexdigest()


def checkpoint_digest(state: dict) -> str:
    h = hashlib.sha256()
    for key in sorted(state):
        value = state[key]
        if value is None:  # not written, so not hashed
            continue
        h.update(key.encode())
        if isinstance(value, list):
            for a in value:
                a = np.ascontiguousarray(a)
                h.update(f"{a.dtype.str}{a.shape}".encode())
                h.update(a.tobytes())
        elif isinstance(value, np.ndarray):
            a = np.ascontiguousarray(value)
            h.update(f"{a.dtype.str}{a.shape}".encode())
            h.update(a.tobytes())
        else:
            h.update(repr(plain(value)).encode())
    return h.hexdigest()


def plain(v):
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, np.generic):
        v = v.item()
    return v


