"""Writer and reader of ampi's weight file, .ampw (byte layout: weights_format/SPEC.md).

numpy and the standard library only. The training export writes with ``write_ampw``; the
C++ engine reads with ``ampi::WeightFile`` (weights_format/weight_file.h). ``read_ampw``
performs the same checks as the C++ reader, with the same messages.

    from weights_format.ampw import write_ampw, read_ampw
    write_ampw("net.ampw", {"conv1.weight": w}, {"arch": "lite", "width": 32}, f16={"conv1.weight"})
    metadata, tensors = read_ampw("net.ampw")

Output is deterministic: the same tensors and metadata (in the same insertion order) give
the same bytes.
"""

import os
import struct
import zlib

import numpy as np

MAGIC = b"AMPW"
VERSION_MAJOR = 1
VERSION_MINOR = 0
ALIGNMENT = 64
MAX_NAME_BYTES = 255
MAX_RANK = 8
MAX_METADATA_ENTRIES = 4096
MAX_TENSORS = 65536
MAX_STRING_BYTES = 1 << 20
MAX_ARRAY_LENGTH = 1 << 20
MAX_TENSOR_BYTES = 1 << 30

# magic, major, minor, metadata count, tensor count, header bytes, data offset, data bytes
PREAMBLE = struct.Struct("<4sHHIIQQQ")
CHECKSUM_BYTES = 4

TYPE_STRING, TYPE_INT, TYPE_FLOAT, TYPE_BOOL, TYPE_INT_ARRAY, TYPE_FLOAT_ARRAY = range(6)
TYPE_NAMES = ("string", "int64", "float64", "bool", "int64[]", "float64[]")
DTYPE_F32, DTYPE_F16 = 0, 1
DTYPES = {DTYPE_F32: np.dtype("<f4"), DTYPE_F16: np.dtype("<f2")}
INT64_MIN, INT64_MAX = -(1 << 63), (1 << 63) - 1


class AmpwError(ValueError):
    """A malformed .ampw file, or input that cannot be written as one."""


def _align(n):
    return (n + ALIGNMENT - 1) // ALIGNMENT * ALIGNMENT


def _crc32(data):
    return zlib.crc32(data) & 0xFFFFFFFF


def _printable(raw):
    """Bytes shown inside a one-line message: printable ASCII as is, the rest as \\xHH."""
    return "".join(chr(b) if 0x20 <= b < 0x7F and b not in b'"\\' else "\\x%02x" % b for b in raw)


# ---- writing ----------------------------------------------------------------------------


def _encode_name(name, what):
    if not isinstance(name, str):
        raise AmpwError("%s: name %r is not a str" % (what, name))
    raw = name.encode("utf-8")
    if not 1 <= len(raw) <= MAX_NAME_BYTES:
        raise AmpwError("%s: name length %d is outside 1..%d" % (what, len(raw), MAX_NAME_BYTES))
    if any(b <= 0x20 or b >= 0x7F for b in raw):
        raise AmpwError('%s: name "%s" has a byte outside printable ASCII without space' % (what, _printable(raw)))
    return struct.pack("<H", len(raw)) + raw


def _metadata_array(value, key):
    """A list, tuple or 1-D numpy array as (type code, little-endian int64 or float64 array)."""
    if len(value) == 0 and not isinstance(value, np.ndarray):
        raise AmpwError("metadata '%s': an empty list has no element type; pass np.array([], np.int64 or np.float64)" % key)
    if not isinstance(value, np.ndarray) and any(isinstance(v, (bool, np.bool_)) for v in value):
        raise AmpwError("metadata '%s': arrays of bool cannot be stored" % key)
    arr = np.asarray(value)
    if arr.ndim != 1:
        raise AmpwError("metadata '%s': arrays must be one-dimensional" % key)
    if arr.dtype.kind in "iu":
        if arr.size and (int(arr.min()) < INT64_MIN or int(arr.max()) > INT64_MAX):
            raise AmpwError("metadata '%s': a value does not fit in int64" % key)
        return TYPE_INT_ARRAY, arr.astype("<i8")
    if arr.dtype.kind == "f":
        return TYPE_FLOAT_ARRAY, arr.astype("<f8")
    raise AmpwError("metadata '%s': array of %s cannot be stored (int64 or float64 only)" % (key, arr.dtype))


def _encode_metadata_value(key, value):
    # bool before int: in Python a bool is an int.
    if isinstance(value, (bool, np.bool_)):
        return struct.pack("<BB", TYPE_BOOL, int(bool(value)))
    if isinstance(value, (int, np.integer)):
        if not INT64_MIN <= int(value) <= INT64_MAX:
            raise AmpwError("metadata '%s': %d does not fit in int64" % (key, value))
        return struct.pack("<Bq", TYPE_INT, int(value))
    if isinstance(value, (float, np.floating)):
        return struct.pack("<Bd", TYPE_FLOAT, float(value))
    if isinstance(value, str):
        raw = value.encode("utf-8")
        if len(raw) > MAX_STRING_BYTES:
            raise AmpwError("metadata '%s': string of %d bytes exceeds the limit of %d" % (key, len(raw), MAX_STRING_BYTES))
        return struct.pack("<BI", TYPE_STRING, len(raw)) + raw
    if isinstance(value, (list, tuple, np.ndarray)):
        code, arr = _metadata_array(value, key)
        if arr.size > MAX_ARRAY_LENGTH:
            raise AmpwError("metadata '%s': array of %d values exceeds the limit of %d" % (key, arr.size, MAX_ARRAY_LENGTH))
        return struct.pack("<BI", code, arr.size) + arr.tobytes()
    raise AmpwError("metadata '%s': values of type %s cannot be stored" % (key, type(value).__name__))


def _encode_tensor_data(name, array, as_f16):
    arr = np.asarray(array)
    if arr.dtype.kind != "f":
        raise AmpwError("tensor '%s': dtype %s is not floating point" % (name, arr.dtype))
    if arr.ndim > MAX_RANK:
        raise AmpwError("tensor '%s': rank %d exceeds the limit of %d" % (name, arr.ndim, MAX_RANK))
    if 0 in arr.shape:
        raise AmpwError("tensor '%s': dimension %d is 0" % (name, arr.shape.index(0)))
    dtype = DTYPE_F16 if as_f16 else DTYPE_F32
    with np.errstate(over="ignore"):  # overflow is reported below, by name
        stored = arr.astype(DTYPES[dtype], order="C")  # unlike ascontiguousarray, keeps rank 0
    overflow = np.isfinite(arr) & ~np.isfinite(stored)
    if overflow.any():
        raise AmpwError("tensor '%s': %d values overflow %s" % (name, int(overflow.sum()), "f16" if as_f16 else "f32"))
    if stored.nbytes > MAX_TENSOR_BYTES:
        raise AmpwError("tensor '%s': %d bytes exceed the limit of %d bytes" % (name, stored.nbytes, MAX_TENSOR_BYTES))
    return dtype, stored


def _layout_tensors(tensors, f16):
    """Table entries and data blobs, each tensor at the next 64-byte boundary."""
    entries, blobs, offset = [], [], 0
    for name, array in tensors.items():
        name_bytes = _encode_name(name, "tensor")
        dtype, stored = _encode_tensor_data(name, array, name in f16)
        data = stored.tobytes()
        offset = _align(offset)
        entries.append(
            name_bytes
            + struct.pack("<BB", dtype, stored.ndim)
            + struct.pack("<%dQ" % stored.ndim, *stored.shape)
            + struct.pack("<QQI", offset, len(data), _crc32(data))
        )
        blobs.append((offset, data))
        offset += len(data)
    return entries, blobs, offset


def encode_ampw(tensors, metadata, f16=()):
    """The bytes of an .ampw file (write_ampw without the file)."""
    unknown = set(f16) - set(tensors)
    if unknown:
        raise AmpwError("f16 names tensors that do not exist: %s" % ", ".join(sorted(unknown)))
    if len(metadata) > MAX_METADATA_ENTRIES:
        raise AmpwError("too many metadata entries: %d (limit %d)" % (len(metadata), MAX_METADATA_ENTRIES))
    if len(tensors) > MAX_TENSORS:
        raise AmpwError("too many tensors: %d (limit %d)" % (len(tensors), MAX_TENSORS))
    meta = b"".join(_encode_name(k, "metadata key") + _encode_metadata_value(k, v) for k, v in metadata.items())
    entries, blobs, data_bytes = _layout_tensors(tensors, set(f16))
    header_bytes = PREAMBLE.size + len(meta) + sum(len(e) for e in entries)
    data_offset = _align(header_bytes + CHECKSUM_BYTES)
    preamble = PREAMBLE.pack(MAGIC, VERSION_MAJOR, VERSION_MINOR, len(metadata), len(tensors),
                             header_bytes, data_offset, data_bytes)
    out = bytearray(data_offset + data_bytes)
    header = preamble + meta + b"".join(entries)
    out[:header_bytes] = header
    out[header_bytes:header_bytes + CHECKSUM_BYTES] = struct.pack("<I", _crc32(header))
    for offset, data in blobs:
        out[data_offset + offset:data_offset + offset + len(data)] = data
    return bytes(out)


def write_ampw(path, tensors, metadata, f16=()):
    """Writes tensors (name -> floating-point numpy array, in numpy dimension order) and
    metadata (key -> str | int | float | bool | list/array of int or float) to `path`.
    Tensors named in `f16` are stored as IEEE half precision, the rest as f32. The file
    appears complete or not at all (written beside it, then renamed)."""
    data = encode_ampw(tensors, metadata, f16)
    tmp = "%s.%d.tmp" % (path, os.getpid())
    try:
        with open(tmp, "xb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# ---- reading ----------------------------------------------------------------------------


class _Cursor:
    """Reads little-endian header fields, never past the header's end."""

    def __init__(self, data, pos, end, fail):
        self.data, self.pos, self.end, self.fail = data, pos, end, fail

    def take(self, n, what):
        if n > self.end - self.pos:
            self.fail("header overrun: %s needs %d bytes at offset %d, header ends at %d" % (what, n, self.pos, self.end))
        raw = self.data[self.pos:self.pos + n]
        self.pos += n
        return raw

    def unpack(self, fmt, what):
        st = struct.Struct("<" + fmt)
        return st.unpack(self.take(st.size, what))[0]

    def name(self, what):
        n = self.unpack("H", what + " name length")
        if not 1 <= n <= MAX_NAME_BYTES:
            self.fail("%s: name length %d is outside 1..%d" % (what, n, MAX_NAME_BYTES))
        raw = self.take(n, what + " name")
        if any(b <= 0x20 or b >= 0x7F for b in raw):
            self.fail('%s: name "%s" has a byte outside printable ASCII without space' % (what, _printable(raw)))
        return bytes(raw).decode("ascii")


def _read_metadata_value(cur, code, what, fail):
    if code == TYPE_STRING:
        n = cur.unpack("I", what + " string length")
        if n > MAX_STRING_BYTES:
            fail("%s: string of %d bytes exceeds the limit of %d" % (what, n, MAX_STRING_BYTES))
        raw = cur.take(n, what + " string")
        try:
            return bytes(raw).decode("utf-8")
        except UnicodeDecodeError:
            fail("%s: string is not valid UTF-8" % what)
    if code == TYPE_INT:
        return cur.unpack("q", what + " value")
    if code == TYPE_FLOAT:
        return cur.unpack("d", what + " value")
    if code == TYPE_BOOL:
        b = cur.unpack("B", what + " value")
        if b > 1:
            fail("%s: bool byte is %d, not 0 or 1" % (what, b))
        return b == 1
    if code in (TYPE_INT_ARRAY, TYPE_FLOAT_ARRAY):
        n = cur.unpack("I", what + " array length")
        if n > MAX_ARRAY_LENGTH:
            fail("%s: array of %d values exceeds the limit of %d" % (what, n, MAX_ARRAY_LENGTH))
        raw = cur.take(8 * n, what + " array")
        return np.frombuffer(raw, dtype="<i8" if code == TYPE_INT_ARRAY else "<f8").copy()
    fail("%s: unknown type code %d" % (what, code))


def _read_tensor_entry(cur, index, data_bytes, fail):
    name = cur.name("tensor entry %d" % index)
    what = "tensor '%s'" % name
    dtype = cur.unpack("B", what + " dtype")
    if dtype not in DTYPES:
        fail("%s: unknown dtype code %d" % (what, dtype))
    rank = cur.unpack("B", what + " rank")
    if rank > MAX_RANK:
        fail("%s: rank %d exceeds the limit of %d" % (what, rank, MAX_RANK))
    itemsize = DTYPES[dtype].itemsize
    shape, elements = [], 1
    for d in range(rank):
        dim = cur.unpack("Q", what + " dimension")
        if dim == 0:
            fail("%s: dimension %d is 0" % (what, d))
        if dim > MAX_TENSOR_BYTES // itemsize // elements:
            fail("%s: dimension %d of %d makes the tensor larger than the limit of %d bytes"
                 % (what, d, dim, MAX_TENSOR_BYTES))
        elements *= dim
        shape.append(dim)
    offset = cur.unpack("Q", what + " offset")
    nbytes = cur.unpack("Q", what + " byte size")
    checksum = cur.unpack("I", what + " checksum")
    dtype_name = "f32" if dtype == DTYPE_F32 else "f16"
    shape_text = "[" + ", ".join(str(d) for d in shape) + "]"
    if nbytes != elements * itemsize:
        fail("%s: byte size %d does not match shape %s of %s (%d bytes)"
             % (what, nbytes, shape_text, dtype_name, elements * itemsize))
    if offset % ALIGNMENT:
        fail("%s: offset %d is not a multiple of %d" % (what, offset, ALIGNMENT))
    if offset > data_bytes or nbytes > data_bytes - offset:
        fail("%s: offset %d + %d bytes is out of range of the %d-byte data section" % (what, offset, nbytes, data_bytes))
    return name, dtype, tuple(shape), offset, nbytes, checksum


def decode_ampw(data, origin="<bytes>"):
    """(metadata, tensors) from the bytes of an .ampw file; raises AmpwError("ORIGIN: problem").
    Metadata arrays come back as int64/float64 numpy arrays, tensors in their stored dtype
    (float32 or float16), in file order."""

    def fail(problem):
        raise AmpwError("%s: %s" % (origin, problem))

    data = memoryview(data).cast("B")
    size = len(data)
    if size == 0:
        fail("empty file")
    if size < PREAMBLE.size:
        fail("truncated: preamble needs %d bytes, file has %d" % (PREAMBLE.size, size))
    magic, major, minor, n_meta, n_tensors, header_bytes, data_offset, data_bytes = PREAMBLE.unpack(data[:PREAMBLE.size])
    if magic != MAGIC:
        fail('bad magic: expected "AMPW", found "%s"' % _printable(magic))
    if major != VERSION_MAJOR:
        fail("unsupported format version %d.%d (this reader reads %d.x)" % (major, minor, VERSION_MAJOR))
    if header_bytes < PREAMBLE.size:
        fail("header size %d is smaller than the %d-byte preamble" % (header_bytes, PREAMBLE.size))
    if header_bytes > size - CHECKSUM_BYTES:
        fail("truncated: header needs %d bytes, file has %d" % (header_bytes + CHECKSUM_BYTES, size))
    stored = struct.unpack("<I", data[header_bytes:header_bytes + CHECKSUM_BYTES])[0]
    computed = _crc32(data[:header_bytes])
    if stored != computed:
        fail("header checksum mismatch: stored 0x%08x, computed 0x%08x" % (stored, computed))
    if n_meta > MAX_METADATA_ENTRIES:
        fail("too many metadata entries: %d (limit %d)" % (n_meta, MAX_METADATA_ENTRIES))
    if n_tensors > MAX_TENSORS:
        fail("too many tensors: %d (limit %d)" % (n_tensors, MAX_TENSORS))
    if data_offset % ALIGNMENT:
        fail("data section offset %d is not a multiple of %d" % (data_offset, ALIGNMENT))
    if data_offset < header_bytes + CHECKSUM_BYTES:
        fail("data section offset %d lies inside the header (%d bytes)" % (data_offset, header_bytes + CHECKSUM_BYTES))

    cur = _Cursor(data, PREAMBLE.size, header_bytes, fail)
    metadata = {}
    for i in range(n_meta):
        key = cur.name("metadata entry %d" % i)
        what = "metadata '%s'" % key
        value = _read_metadata_value(cur, cur.unpack("B", what + " type"), what, fail)
        if key in metadata:
            fail("duplicate metadata key '%s'" % key)
        metadata[key] = value
    entries, names = [], set()
    for i in range(n_tensors):
        entry = _read_tensor_entry(cur, i, data_bytes, fail)
        if entry[0] in names:
            fail("duplicate tensor name '%s'" % entry[0])
        names.add(entry[0])
        entries.append(entry)
    if cur.pos != header_bytes and minor <= VERSION_MINOR:
        fail("header has %d unread bytes after the tensor table" % (header_bytes - cur.pos))

    if data_offset > size or data_bytes > size - data_offset:
        fail("truncated: data section of %d bytes at offset %d, file has %d bytes" % (data_bytes, data_offset, size))
    if data_bytes < size - data_offset:
        fail("%d unexpected bytes after the data section" % (size - data_offset - data_bytes))
    _check_overlaps(entries, data_offset, fail)
    tensors = {}
    for name, dtype, shape, offset, nbytes, checksum in entries:
        start = data_offset + offset
        raw = data[start:start + nbytes]
        if _crc32(raw) != checksum:
            fail("tensor '%s': data checksum mismatch: stored 0x%08x, computed 0x%08x" % (name, checksum, _crc32(raw)))
        tensors[name] = np.frombuffer(raw, dtype=DTYPES[dtype]).reshape(shape).copy()
    return metadata, tensors


def _check_overlaps(entries, data_offset, fail):
    spans = sorted((data_offset + e[3], data_offset + e[3] + e[4], e[0]) for e in entries)
    for (a_start, a_end, a), (b_start, b_end, b) in zip(spans, spans[1:]):
        if a_end > b_start:
            fail("tensors '%s' and '%s' overlap: bytes [%d, %d) and [%d, %d)" % (a, b, a_start, a_end, b_start, b_end))


def read_ampw(path):
    """(metadata, tensors) of the .ampw file at `path`, validated like the C++ reader."""
    with open(path, "rb") as f:
        return decode_ampw(f.read(), path)
