"""The shared reader: regular files only, size and depth bounded, schema checked."""
from __future__ import annotations

import os

import pytest

from trilith_xval.scenes.safe_read import check_schema, read_bytes, read_json, read_text


def test_special_files_are_refused_without_blocking(tmp_path):
    os.mkfifo(tmp_path / "fifo")  # opened, this would block: it is never opened
    for path in (tmp_path / "fifo", "/dev/zero", tmp_path):
        with pytest.raises(ValueError, match="where is not a regular file"):
            read_bytes(path, "where", 10)
    with pytest.raises(ValueError, match="where does not exist"):
        read_bytes(tmp_path / "none", "where", 10)


def test_size_is_capped_before_reading(tmp_path):
    (tmp_path / "f").write_bytes(b"x" * 11)
    assert read_bytes(tmp_path / "f", "w", 11) == b"x" * 11
    with pytest.raises(ValueError, match="w is larger than 10 bytes"):
        read_bytes(tmp_path / "f", "w", 10)


def test_text_drops_a_bom_and_refuses_binary(tmp_path):
    (tmp_path / "t").write_bytes(b"\xef\xbb\xbfabc")
    assert read_text(tmp_path / "t", "w", 100) == "abc"
    (tmp_path / "b").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ValueError, match="not a UTF-8 text file"):
        read_text(tmp_path / "b", "w", 100)


def test_json_depth_counts_brackets_outside_strings(tmp_path):
    (tmp_path / "s.json").write_text('{"a": "[[[[[[[[[[[[", "b": [[1]]}')
    assert read_json(tmp_path / "s.json", "w", max_depth=3)["b"] == [[1]]
    (tmp_path / "d.json").write_text("[" * 5 + "]" * 5)
    with pytest.raises(ValueError, match="nested deeper than 4 levels"):
        read_json(tmp_path / "d.json", "w", max_depth=4)
    (tmp_path / "e.json").write_text('{"a": ')
    with pytest.raises(ValueError, match="w is not valid JSON"):
        read_json(tmp_path / "e.json", "w")


def test_schema_versions():
    check_schema({"schema_version": 2}, "w", (1, 2))
    check_schema({}, "w", (1,))  # no version: the first
    for doc, needle in (({"schema_version": 999}, "schema_version 999"),
                        ({"schema_version": True}, "schema_version True"),
                        ([], "not a JSON object")):
        with pytest.raises(ValueError, match=needle):
            check_schema(doc, "w", (1,))
