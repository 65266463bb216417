"""The store's file: marker, identification, migration, entry digests."""
from __future__ import annotations

import sqlite3

import pytest

from trilith_xval.compare.run import store_db
from trilith_xval.compare.run.store import DB_NAME, RunStore


def test_a_new_store_carries_the_marker_and_no_temporary(tmp_path):
    store = RunStore(tmp_path / "c")
    store.put("k", 1.0, kind="demo", label="demo", cost=0.0)
    store.close()
    db = tmp_path / "c" / DB_NAME
    assert store_db.header_is_ours(db)
    assert store_db.identify(db, 1.0) == "current"
    assert store_db.stale_temporaries(db.parent, DB_NAME) == []
    store_db.create(db)  # a second creator finds it there: nothing changes
    assert RunStore(tmp_path / "c").get("k") == 1.0


def test_the_digest_binds_the_value_to_its_key():
    assert store_db.entry_digest("a", b"v") != store_db.entry_digest("b", b"v")
    assert store_db.entry_digest("a", b"v") != store_db.entry_digest("a", b"w")
    assert store_db.entry_digest("a", b"v") == store_db.entry_digest("a", b"v")


def test_a_proven_entry_is_kept_and_a_failing_one_replaced(tmp_path):
    store = RunStore(tmp_path)
    store.put("k", {"x": 1.0}, kind="demo", label="demo", cost=0.0)
    created = store.created()["k"]
    store.put("k", {"x": 1.0}, kind="demo", label="demo", cost=0.0)
    assert store.created()["k"] == created  # same key, proven: not rewritten
    store._conn.execute("UPDATE runs SET digest = 'f00' WHERE key = 'k'")
    assert store.get("k") is None and len(store.verify()[1]) == 1
    store.put("k", {"x": 1.0}, kind="demo", label="demo", cost=0.0)
    assert store.get("k") == {"x": 1.0} and store.verify() == (1, [])
    assert store.prune({"another"}) == 1  # its code version '' is not kept
    store.close()


@pytest.mark.parametrize("sql, needle", [
    ("CREATE TABLE other (x)", r"application id 0x0, tables \['other', 't'\]"),
    ("PRAGMA application_id = 7", "application id 0x7: another program"),
])
def test_foreign_databases_are_named(tmp_path, sql, needle):
    con = sqlite3.connect(tmp_path / DB_NAME)
    con.execute(sql)
    con.execute("CREATE TABLE IF NOT EXISTS t (x)")
    con.commit()
    con.close()
    with pytest.raises(store_db.NotAStore, match=needle):
        store_db.identify(tmp_path / DB_NAME, 1.0)


def test_a_newer_schema_is_refused_not_rewritten(tmp_path):
    RunStore(tmp_path).create()
    con = sqlite3.connect(tmp_path / DB_NAME)
    con.execute(f"PRAGMA user_version = {store_db.SCHEMA_VERSION + 1}")
    con.commit()
    con.close()
    with pytest.raises(ValueError, match="newer version"):
        RunStore(tmp_path)
