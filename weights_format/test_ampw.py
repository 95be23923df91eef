"""Tests of the Python .ampw writer and reader (run by ctest as weights_format_python):

    /usr/bin/python3 weights_format/test_ampw.py
"""

import os
import struct
import sys
import tempfile
import unittest
import zlib

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, REPO)
sys.path.insert(0, os.path.join(REPO, "tests", "fixtures", "weights"))
from weights_format.ampw import AmpwError, decode_ampw, encode_ampw, read_ampw, write_ampw  # noqa: E402
from make_small import small_contents  # noqa: E402

SEED = 1234


def random_tensors(seed):
    rng = np.random.default_rng(seed)
    return {
        "stem.weight": rng.standard_normal((8, 3, 3, 3)).astype(np.float32),
        "stem.bias": rng.standard_normal(8).astype(np.float32),
        "head.scale": np.float32(rng.standard_normal()) * np.ones((), np.float32),
        "blocks.0.dw": rng.standard_normal((1, 5, 5, 16, 1, 1, 1, 2)).astype(np.float64),
        "blocks.0.pw": rng.standard_normal((16, 7)).astype(np.float32),
    }


def reseal(data):
    """A damaged header with a valid checksum: what a buggy writer would produce."""
    data = bytearray(data)
    header_bytes = struct.unpack_from("<Q", data, 16)[0]
    struct.pack_into("<I", data, header_bytes, zlib.crc32(bytes(data[:header_bytes])) & 0xFFFFFFFF)
    return bytes(data)


def tensor_entry_offset(data, name):
    """Position of the 'offset' field of tensor `name` in the header."""
    n_meta, n_tensors = struct.unpack_from("<II", data, 8)
    pos = 40
    for _ in range(n_meta):
        pos += 2 + struct.unpack_from("<H", data, pos)[0]
        code = data[pos]
        count = struct.unpack_from("<I", data, pos + 1)[0] if code in (0, 4, 5) else 0
        pos += 1 + (4 + count, 8, 8, 1, 4 + 8 * count, 4 + 8 * count)[code]
    for _ in range(n_tensors):
        length = struct.unpack_from("<H", data, pos)[0]
        entry_name = data[pos + 2:pos + 2 + length].decode()
        rank = data[pos + 2 + length + 1]
        offset_field = pos + 2 + length + 2 + 8 * rank
        if entry_name == name:
            return offset_field
        pos = offset_field + 8 + 8 + 4
    raise KeyError(name)


class RoundTrip(unittest.TestCase):
    def test_tensors_and_metadata_round_trip_exactly(self):
        tensors = random_tensors(SEED)
        metadata = {"arch": "lite \u2713", "width": -7, "lr": 1e-3, "train": True, "eval": False,
                    "strides": [1, 2, 2], "scales": (0.5, 0.25), "ints": np.array([5, 6], np.uint8),
                    "none": np.array([], np.int64)}
        got_meta, got = decode_ampw(encode_ampw(tensors, metadata, f16={"blocks.0.pw"}))
        self.assertEqual(list(got), list(tensors))
        for name, array in tensors.items():
            expected = array.astype(np.float16 if name == "blocks.0.pw" else np.float32)
            self.assertEqual(got[name].dtype, expected.dtype, name)
            self.assertEqual(got[name].shape, expected.shape, name)
            np.testing.assert_array_equal(got[name], expected, err_msg="%s (seed %d)" % (name, SEED))
        self.assertEqual(list(got_meta), list(metadata))
        for key in ("arch", "width", "lr", "train", "eval"):
            self.assertEqual(got_meta[key], metadata[key], key)
            self.assertIs(type(got_meta[key]), type(metadata[key]), key)
        self.assertEqual(got_meta["strides"].dtype, np.int64)
        self.assertEqual(got_meta["scales"].dtype, np.float64)
        np.testing.assert_array_equal(got_meta["strides"], [1, 2, 2])
        np.testing.assert_array_equal(got_meta["ints"], [5, 6])
        self.assertEqual(got_meta["none"].dtype, np.int64)
        self.assertEqual(got_meta["none"].size, 0)

    def test_data_is_64_byte_aligned_and_header_fields_consistent(self):
        data = encode_ampw(random_tensors(SEED), {"a": 1})
        magic, major, minor, n_meta, n_tensors, header_bytes, data_offset, data_bytes = \
            struct.unpack_from("<4sHHIIQQQ", data)
        self.assertEqual((magic, major, minor, n_meta, n_tensors), (b"AMPW", 1, 0, 1, 5))
        self.assertEqual(data_offset % 64, 0)
        self.assertEqual(len(data), data_offset + data_bytes)
        for name in random_tensors(SEED):
            self.assertEqual(struct.unpack_from("<Q", data, tensor_entry_offset(data, name))[0] % 64, 0, name)

    def test_empty_file_of_no_tensors(self):
        self.assertEqual(decode_ampw(encode_ampw({}, {})), ({}, {}))


class Determinism(unittest.TestCase):
    def test_same_input_same_bytes(self):
        self.assertEqual(encode_ampw(random_tensors(SEED), {"k": 1.5}, {"stem.bias"}),
                         encode_ampw(random_tensors(SEED), {"k": 1.5}, {"stem.bias"}))

    def test_committed_fixture_is_what_its_generator_writes(self):
        tensors, metadata, f16 = small_contents()
        with open(os.path.join(REPO, "tests", "fixtures", "weights", "small.ampw"), "rb") as f:
            self.assertEqual(f.read(), encode_ampw(tensors, metadata, f16))

    def test_write_and_read_files(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "w.ampw")
            write_ampw(path, random_tensors(SEED), {"k": "v"})
            self.assertEqual(os.listdir(tmp), ["w.ampw"])
            metadata, tensors = read_ampw(path)
            self.assertEqual(metadata, {"k": "v"})
            np.testing.assert_array_equal(tensors["stem.bias"], random_tensors(SEED)["stem.bias"])


class WriterRefusesBadInput(unittest.TestCase):
    def check(self, tensors, metadata, expected, f16=()):
        with self.assertRaises(AmpwError) as ctx:
            encode_ampw(tensors, metadata, f16)
        self.assertIn(expected, str(ctx.exception))

    def test_bad_input(self):
        x = np.ones(3, np.float32)
        self.check({"w": np.ones(3, np.int32)}, {}, "is not floating point")
        self.check({"w": np.ones((2, 0))}, {}, "dimension 1 is 0")
        self.check({"w": np.ones((1,) * 9)}, {}, "rank 9 exceeds the limit of 8")
        self.check({"w": np.array([1e5, 1.0])}, {}, "1 values overflow f16", f16={"w"})
        self.check({"w": x}, {}, "f16 names tensors that do not exist: v", f16={"v"})
        self.check({"a b": x}, {}, 'name "a b" has a byte outside printable ASCII')
        self.check({"": x}, {}, "name length 0 is outside 1..255")
        self.check({}, {"k": []}, "an empty list has no element type")
        self.check({}, {"k": [True, False]}, "arrays of bool cannot be stored")
        self.check({}, {"k": 1 << 63}, "does not fit in int64")
        self.check({}, {"k": None}, "values of type NoneType cannot be stored")

    def test_failed_write_leaves_nothing(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "w.ampw")
            with self.assertRaises(AmpwError):
                write_ampw(path, {"w": np.ones(2, np.int8)}, {})
            self.assertEqual(os.listdir(tmp), [])


class ReaderRefusesDamage(unittest.TestCase):
    def setUp(self):
        tensors, metadata, f16 = small_contents()
        self.good = encode_ampw(tensors, metadata, f16)
        self.header_bytes = struct.unpack_from("<Q", self.good, 16)[0]
        self.data_offset = struct.unpack_from("<Q", self.good, 24)[0]

    def message(self, data):
        with self.assertRaises(AmpwError) as ctx:
            decode_ampw(data, "x.ampw")
        text = str(ctx.exception)
        self.assertTrue(text.startswith("x.ampw: "), text)
        self.assertNotIn("\n", text)
        return text

    def damaged(self, pos, value, fmt, seal=True):
        data = bytearray(self.good)
        struct.pack_into("<" + fmt, data, pos, value)
        return reseal(data) if seal else bytes(data)

    def test_every_truncation(self):
        self.assertEqual(self.message(b""), "x.ampw: empty file")
        for size in range(1, len(self.good)):
            self.assertIn("truncated", self.message(self.good[:size]), "size %d" % size)

    def test_same_messages_as_the_cpp_reader(self):
        # The C++ test (tests/weights_format/test_weight_file.cpp) expects the same texts.
        conv1_bias = tensor_entry_offset(self.good, "conv1.bias")
        cases = [
            (self.good[:300], "truncated: header needs 746 bytes, file has 300"),
            (self.good[:-1], "truncated: data section of 588 bytes at offset 768, file has 1355 bytes"),
            (b"XMPW" + self.good[4:], 'bad magic: expected "AMPW", found "XMPW"'),
            (self.damaged(4, 2, "H", seal=False), "unsupported format version 2.0 (this reader reads 1.x)"),
            (self.damaged(100, 0x55, "B", seal=False), "header checksum mismatch"),
            (self.damaged(self.data_offset + 320, 0x55, "B", seal=False),
             "tensor 'conv1.bias': data checksum mismatch"),
            (self.damaged(conv1_bias, 328, "Q"), "tensor 'conv1.bias': offset 328 is not a multiple of 64"),
            (self.damaged(conv1_bias, 1 << 40, "Q"),
             "tensor 'conv1.bias': offset 1099511627776 + 16 bytes is out of range of the 588-byte data section"),
            (self.damaged(conv1_bias, 0, "Q"),
             "tensors 'conv1.bias' and 'conv1.weight' overlap: bytes [768, 784) and [768, 1056)"),
            (self.damaged(conv1_bias - 8, 1 << 40, "Q"),
             "tensor 'conv1.bias': dimension 0 of 1099511627776 makes the tensor larger than the limit"),
            (self.damaged(12, 70000, "I"), "too many tensors: 70000 (limit 65536)"),
            (self.damaged(16, self.header_bytes + 4, "Q"), "header has 4 unread bytes after the tensor table"),
            (self.good + bytes(8), "8 unexpected bytes after the data section"),
        ]
        seen = set()
        for data, expected in cases:
            text = self.message(data)
            self.assertIn(expected, text)
            self.assertNotIn(text, seen)
            seen.add(text)

    def test_duplicate_names(self):
        data = bytearray(self.good)
        at = bytes(data).index(b"block1.gain")
        data[at:at + 11] = b"block0.gain"
        self.assertIn("duplicate tensor name 'block0.gain'", self.message(reseal(data)))
        data = bytearray(self.good)
        at = bytes(data).index(b"model.depth")
        data[at:at + 11] = b"model.width"
        self.assertIn("duplicate metadata key 'model.width'", self.message(reseal(data)))

    def test_newer_minor_version_is_read(self):
        data = bytearray(self.good)
        struct.pack_into("<H", data, 6, 1)
        struct.pack_into("<Q", data, 16, self.header_bytes + 4)
        metadata, _ = decode_ampw(reseal(data))
        self.assertEqual(metadata["model.width"], 8)


if __name__ == "__main__":
    unittest.main()
