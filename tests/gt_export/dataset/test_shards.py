"""WebDataset tar shards: read back by webdataset itself and by tarfile, bit-identical to the
sample folders; splits kept apart; reproducible; never touching files that are not ours."""

from __future__ import annotations

import hashlib
import io
import json
import tarfile

import numpy as np
import pytest

from spectrinsic.errors import DatasetError
from spectrinsic.gt_export import load_sample

wds = pytest.importorskip("webdataset", reason="the shards extra (webdataset) is in the dev extra")

from spectrinsic.gt_export.dataset.shards import (  # noqa: E402
    SHARD_INDEX,
    shard_dataset,
    shard_urls,
    write_shards,
)


def _sha(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_webdataset_reads_every_layer_bit_identical(built, tmp_path_factory):
    out = tmp_path_factory.mktemp("shards")
    written = write_shards(built, out)
    # webdataset's own reader, with its own npy decoder: independent of our _decode
    records = list(wds.WebDataset(shard_urls(out), shardshuffle=False).decode())
    entries = json.loads((out / SHARD_INDEX).read_text())["entries"]
    assert sorted(r["__key__"] for r in records) == ["a-one", "b-two"]
    for record in records:
        truth = load_sample(built / record["__key__"])
        arrays = {k: v for k, v in truth.items() if isinstance(v, np.ndarray)}
        got = {entries[k]: v for k, v in record.items() if k.endswith(".npy")}
        assert set(got) == set(arrays) and {"image", "reflectance", "shading", "mask"} <= set(got)
        for key, value in arrays.items():
            assert got[key].dtype == value.dtype and np.array_equal(got[key], value), key
        assert record["meta.json"]["sample_id"] == record["__key__"]
    assert set(written.layers) == set(got)


def test_shards_follow_the_manifest_splits(built, tmp_path_factory):
    out = tmp_path_factory.mktemp("shards")
    write_shards(built, out, samples_per_shard=1)
    splits = json.loads((built / "manifest.json").read_text())["splits"]
    index = json.loads((out / SHARD_INDEX).read_text())
    assert index["complete"] is True
    for split, ids in splits.items():
        assert index["splits"][split]["samples"] == len(ids)
        if not ids:  # fewer scenes than splits: an empty split is an error naming it
            with pytest.raises(
                DatasetError, match=f"split '{split}' .* is empty: the dataset had 1 scene"
            ):
                shard_dataset(out, split)
            continue
        assert sorted(item["sample_id"] for item in shard_dataset(out, split)) == sorted(ids)
        for name in index["splits"][split]["shards"]:
            with tarfile.open(out / name) as tar:  # plain tar, one sample per shard here
                keys = {m.name.split(".", 1)[0] for m in tar.getmembers()}
            assert len(keys) == 1 and keys <= set(ids)


def test_same_dataset_gives_byte_identical_shards(built, tmp_path_factory):
    a, b = tmp_path_factory.mktemp("a"), tmp_path_factory.mktemp("b")
    write_shards(built, a)
    write_shards(built, b)
    names = sorted(p.name for p in a.glob("*.tar"))
    assert names and names == sorted(p.name for p in b.glob("*.tar"))
    assert [_sha(a / n) for n in names] == [_sha(b / n) for n in names]
    index = json.loads((a / SHARD_INDEX).read_text())
    assert index["files"] == {n: _sha(a / n) for n in names}


def test_refuses_a_folder_with_foreign_files_and_keeps_them(built, tmp_path_factory):
    out = tmp_path_factory.mktemp("shards")
    (out / "notes.txt").write_text("mine")
    with pytest.raises(DatasetError, match="did not write"):
        write_shards(built, out)
    assert (out / "notes.txt").read_text() == "mine" and not (out / SHARD_INDEX).exists()


def test_interrupted_export_is_not_complete_and_resumes(built, tmp_path_factory, monkeypatch):
    import spectrinsic.gt_export.dataset.shards as shards

    out = tmp_path_factory.mktemp("shards")
    real = shards._encode
    calls = {"n": 0}

    def failing(sample):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt
        return real(sample)

    monkeypatch.setattr(shards, "_encode", failing)
    with pytest.raises(KeyboardInterrupt):
        write_shards(built, out, samples_per_shard=1)
    assert not any(p.name.startswith(".spectrinsic-tmp-") for p in out.iterdir())
    with pytest.raises(DatasetError, match="interrupted"):
        shard_urls(out)
    monkeypatch.setattr(shards, "_encode", real)
    write_shards(built, out, samples_per_shard=1)  # the half-done folder is ours: resumes
    assert sorted(item["sample_id"] for item in shard_dataset(out)) == ["a-one", "b-two"]


def test_fewer_shards_remove_only_our_stale_ones(built, tmp_path_factory):
    out = tmp_path_factory.mktemp("shards")
    write_shards(built, out, samples_per_shard=1)
    before = {p.name for p in out.glob("*.tar")}
    write_shards(built, out, samples_per_shard=1000)
    after = {p.name for p in out.glob("*.tar")}
    index = json.loads((out / SHARD_INDEX).read_text())
    assert after == set(index["files"]) and len(after) <= len(before)


def test_layer_subset_and_bad_shard_size(built, tmp_path_factory):
    out = tmp_path_factory.mktemp("shards")
    write_shards(built, out, layers=["image", "shading"])
    item = next(iter(shard_dataset(out)))
    assert set(k for k, v in item.items() if isinstance(v, np.ndarray)) == {"image", "shading"}
    with pytest.raises(DatasetError, match=">= 1"):
        write_shards(built, out, samples_per_shard=0)


def test_tar_members_carry_no_time_or_owner(built, tmp_path_factory):
    out = tmp_path_factory.mktemp("shards")
    write_shards(built, out)
    with tarfile.open(next(out.glob("*.tar"))) as tar:
        members = tar.getmembers()
        assert members and all(m.mtime == 0 and m.uname == "spectrinsic" for m in members)
        first = next(m for m in members if m.name.endswith(".image.npy"))
        array = np.load(io.BytesIO(tar.extractfile(first).read()))
    assert array.ndim == 3 and array.shape[-1] == 3 and array.dtype == np.float32


def test_export_verb_writes_shards_and_rejects_bad_input(built, tmp_path_factory, capsys):
    from spectrinsic.cli import main

    out = tmp_path_factory.mktemp("cli") / "shards"
    assert main(["-q", "export", str(built), "--out", str(out), "--layers", "image,mask"]) == 0
    assert "shards:" in capsys.readouterr().out
    assert sorted(item["sample_id"] for item in shard_dataset(out)) == ["a-one", "b-two"]
    assert main(["-q", "export", str(out), "--out", str(out / "x")]) == 2
    assert "no manifest.json" in capsys.readouterr().err


def test_a_shard_with_flipped_bytes_is_refused_before_any_item(built, tmp_path_factory):
    """8 bytes flipped inside a shard's data (as in the issue: a depth read back as 9.5e14)."""
    out = tmp_path_factory.mktemp("shards")
    write_shards(built, out, samples_per_shard=1)
    assert len(list(shard_dataset(out))) == 2  # intact: every item
    shard = sorted(out.glob("*.tar"))[0]
    data = bytearray(shard.read_bytes())
    middle = len(data) // 2
    data[middle : middle + 8] = bytes(b ^ 0xFF for b in data[middle : middle + 8])
    shard.write_bytes(bytes(data))
    with pytest.raises(
        DatasetError, match=f"{shard.name}: does not match its SHA-256 in {SHARD_INDEX}"
    ):
        shard_dataset(out)
