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
    # said, as `lucent merge` says it (a script's output was an image of fewer samples without a
    # word)
    with pytest.warns(lucent.LucentWarning,
                      match=r"^samples \[4, 12\) are missing: the image has fewer samples$"):
        merged = lucent.merge_parts([a], expect=(0, 12))
    assert merged.missing == [(4, 12)]
    assert "missing [4, 12)" in repr(merged)
    # refused before the output is written
    out = tmp_path / "m.exr"
    with pytest.raises(lucent.Error, match=r"samples \[4, 12\) are missing \(complete\)"):
        lucent.merge_parts([a], output=out, expect=(0, 12), complete=True)
    with pytest.raises(lucent.Error, match=r"outside expect \[0, 2\)"):
        lucent.merge_parts([a], output=out, expect=(0, 2))
    assert not out.exists()
    # the output is checked before any part is read (here one that does not exist), and is never
    # one of them
    with pytest.raises(lucent.Error, match=r"unknown output format '\.jpg'"):
        lucent.merge_parts([tmp_path / "none.exr"], output=tmp_path / "m.jpg")
    with pytest.raises(lucent.Error, match="is an input of the merge"):
        lucent.merge_parts([a], output=a)
    # expect's bounds are named
    with pytest.raises(ValueError, match=r"expect begin must be an integer in \[0, "):
        lucent.merge_parts([a], expect=(-1, 4))
    with pytest.raises(ValueError, match=r"expect end must be an integer in \[1, "):
        lucent.merge_parts([a], expect=(0, 2**64))
    with pytest.raises(TypeError, match=r"expect must be a tuple \(begin, end\)"):
        lucent.merge_parts([a], expect=[0, 4])


def test_a_render_cut_short_records_the_range_it_was_asked_for(small_scene, tmp_path):
    part = tmp_path / "p.exr"
    with session() as r:
        r.set_scene(small_scene)
        r.reset(first_sample=8)
        r.render(4)  # (as if a time limit had stopped a render of [8, 16))
        r.write_part(part, requested=(8, 16))
        assert lucent.read_part_info(part).samples == [(8, 12)]
        assert lucent.read_part_info(part).requested == [(8, 16)]
        with pytest.warns(lucent.LucentWarning, match="are missing"):
            assert lucent.merge_parts([part]).missing == [(0, 8), (12, 16)]
        # a range that does not hold the samples rendered
        with pytest.raises(lucent.Error, match=r"lie outside the requested \[0, 10\)"):
            r.write_part(tmp_path / "q.exr", requested=(0, 10))
        with pytest.raises(ValueError, match="requested must be"):
            r.write_part(tmp_path / "q.exr", requested=(9, 9))
    assert not (tmp_path / "q.exr").exists()


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
        with pytest.raises(TypeError, match="^compression must be a str, got bytes$"):
            r.write_part(tmp_path / "p.exr", compression=b"zip")
        with pytest.raises(lucent.Error, match="write_part writes a part file: use an .exr name"):
            r.write_part(tmp_path / "p.png")
    assert not (tmp_path / "p.exr").exists() and not (tmp_path / "p.png").exists()
    # never over a file the scene reads (an environment map in OpenEXR)
    sky = tmp_path / "sky.exr"
    lucent.write_image(sky, np.full((4, 8, 3), 0.5, np.float32))
    d = {"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
         "film": {"width": 8, "height": 6},
         "lights": [{"type": "environment", "file": "sky.exr"}]}
    with session(specialize=False) as r:  # the full kernel, which other tests build too
        r.set_scene(lucent.scene_from_dict(d, base_dir=str(tmp_path)))
        r.render(1)
        with pytest.raises(lucent.Error, match="sky.exr"):
            r.write_part(sky)
    np.testing.assert_array_equal(lucent.read_image(sky), np.full((4, 8, 3), 0.5, np.float32))
    with pytest.raises(ValueError, match="no part files given"):
        lucent.merge_parts([])
    with pytest.raises(ValueError, match=r"expect must be \(begin, end\)"):
        lucent.merge_parts([tmp_path / "p.exr"], expect=(4, 4))
    with pytest.raises(lucent.Error, match="p.exr"):
        lucent.read_part_info(tmp_path / "p.exr")



def test_write_part_refuses_the_scenes_files_after_a_change_of_directory(tmp_path, small_dict,
                                                                         monkeypatch):
    # the scene's relative names meant other files after os.chdir, and a part was written over
    # its environment map (the Python tester's find): the names set_scene resolved are refused
    import json
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path)
    lucent.write_image("env.exr", np.full((4, 8, 3), 0.5, np.float32))
    small_dict["lights"].append({"type": "environment_map", "file": "env.exr"})
    (tmp_path / "s.json").write_text(json.dumps(small_dict))
    scene = lucent.load_scene("s.json")
    before = (tmp_path / "env.exr").read_bytes()
    with session() as r:
        r.set_scene(scene)
        r.render(2)
        with pytest.raises(lucent.Error, match="is an input of this render"):
            r.write_part("env.exr")
        monkeypatch.chdir(tmp_path / "sub")
        with pytest.raises(lucent.Error, match="is an input of this render"):
            r.write_part(tmp_path / "env.exr")
        r.write_part(tmp_path / "p.exr")  # (another name is written)
    assert (tmp_path / "env.exr").read_bytes() == before
    assert lucent.read_part_info(tmp_path / "p.exr").samples == [(0, 2)]
