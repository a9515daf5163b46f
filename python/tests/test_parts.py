"""Sample-range renders ("parts") from Python: Renderer.write_part, read_part_info and merge_parts,
against a single render of the union of the ranges and `lucent merge`'s rules (docs/parts.md)."""
import numpy as np
import pytest

import lucent
from conftest import session


def render_part(scene, path, first, spp, **kwargs):
    """Renders samples [first, first + spp) of `scene` in a session of its own and writes them."""
    with session() as r:
        r.set_scene(scene)
        r.reset(first_sample=first)
        r.render(spp)
        r.write_part(path, **kwargs)


def test_parts_merge_into_the_render_of_their_union(small_scene, tmp_path):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    render_part(small_scene, a, 0, 4)
    render_part(small_scene, b, 4, 4, compression="piz")
    info = lucent.read_part_info(b)
    assert (info.width, info.height) == (16, 12)
    assert info.samples == [(4, 8)] and info.requested == [(4, 8)]
    assert info.seed == small_scene.integrator.seed and info.integrator == "path"
    # given in any order: added in ascending order of their first sample
    merged = lucent.merge_parts([b, a], output=tmp_path / "m.exr")
    assert merged.info.samples == [(0, 8)] and merged.missing == []
    assert merged.min_spp == merged.max_spp == 8
    with session() as r:
        r.set_scene(small_scene)
        r.render(8)
        single = r.result()
    # the same samples: equal but for the order of float additions in the passes
    np.testing.assert_allclose(merged.result.mean, single.mean, rtol=1e-5, atol=1e-7)
    np.testing.assert_array_equal(merged.result.samples, single.samples)
    assert merged.result.spp == 8
    # the output is a part file of the union, which merges again
    assert lucent.read_part_info(tmp_path / "m.exr").samples == [(0, 8)]
    again = lucent.merge_parts([tmp_path / "m.exr"])
    np.testing.assert_array_equal(again.result.mean, merged.result.mean)


def test_missing_and_overlapping_ranges(small_scene, tmp_path):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    render_part(small_scene, a, 0, 4)
    render_part(small_scene, b, 2, 4)
    with pytest.raises(lucent.Error, match=r"samples \[2, 6\) overlap .*a\.exr's \[0, 4\)"):
        lucent.merge_parts([a, b])
    merged = lucent.merge_parts([a], expect=(0, 12))
    assert merged.missing == [(4, 12)]
    assert "missing [4, 12)" in repr(merged)
    with pytest.raises(lucent.Error, match=r"samples \[4, 12\) are missing \(complete\)"):
        lucent.merge_parts([a], expect=(0, 12), complete=True)
    with pytest.raises(lucent.Error, match=r"outside expect \[0, 2\)"):
        lucent.merge_parts([a], expect=(0, 2))
    # the output is checked before any part is read, and never one of them
    with pytest.raises(lucent.Error, match="is an input of the merge"):
        lucent.merge_parts([a], output=a)
    with pytest.raises(lucent.Error, match=r"unknown output format '\.jpg'"):
        lucent.merge_parts([a], output=tmp_path / "m.jpg")
    assert not (tmp_path / "m.jpg").exists()


def test_refusals(small_scene, tmp_path):
    with session() as r:
        with pytest.raises(lucent.Error, match="no scene"):
            r.write_part(tmp_path / "p.exr")
        r.set_scene(small_scene)
        with pytest.raises(lucent.Error, match="holds no samples to write"):
            r.write_part(tmp_path / "p.exr")
        r.render(1)
        with pytest.raises(ValueError, match="compression must be 'zip' or 'piz', got 'lzw'"):
            r.write_part(tmp_path / "p.exr", compression="lzw")
    assert not (tmp_path / "p.exr").exists()
    with pytest.raises(ValueError, match="no part files given"):
        lucent.merge_parts([])
    with pytest.raises(ValueError, match=r"expect must be \(begin, end\)"):
        lucent.merge_parts([tmp_path / "p.exr"], expect=(4, 4))
    with pytest.raises(lucent.Error, match="p.exr"):
        lucent.read_part_info(tmp_path / "p.exr")
