"""planarvo.build_mosaic and planarvo.read_tum: the image and its map_server YAML as the file
says, the placement against the data set's own camera footprint, progress and cancellation, and
bad input."""
import re

import numpy as np
import pytest

import planarvo


def _truth(ds):
    n = len(ds)
    t = np.array([ds.frame_data(i).timestamp for i in range(n)])
    p = np.array([ds.frame_data(i).groundtruth.as_array() for i in range(n)])
    return t, p


def test_read_tum_reads_what_write_tum_wrote(tmp_path):
    t = np.array([0.0, 0.5, 1.25])
    p = np.array([[0.0, 0.0, 0.0], [0.1, -0.2, 0.3], [1e-9, 2.5, -3.0]])
    planarvo.write_tum(tmp_path / "t.txt", t, p)
    t2, p2 = planarvo.read_tum(tmp_path / "t.txt")
    assert np.array_equal(t2, t)
    assert np.allclose(p2, p, rtol=0, atol=1e-15)
    (tmp_path / "empty.txt").write_text("# timestamp x y z qx qy qz qw\n")
    t3, p3 = planarvo.read_tum(tmp_path / "empty.txt")
    assert t3.shape == (0,) and p3.shape == (0, 3)


def test_mosaic_image_yaml_and_placement(context, drive, tmp_path):
    with planarvo.Dataset(drive) as ds:
        t, p = _truth(ds)
        e = ds.info.extrinsics_gt
        seen = []
        m = planarvo.build_mosaic(context, ds, e, t, p, resolution=0.002, progress=lambda f, s: seen.append(f))
        info, image = m.info, m.image
        m.save(tmp_path / "floor.png")
        m.save_preview(tmp_path / "preview.png")
    assert seen and seen[-1] == 1.0
    assert image.shape == (info.height, info.width)
    assert int((image > 0).sum()) == info.covered_pixels > 1000
    assert info.frames_given == len(t) and 1 <= info.frames_used <= len(t)
    Image = pytest.importorskip("PIL.Image")
    assert np.array_equal(np.asarray(Image.open(tmp_path / "floor.png")), image)
    # The preview: the same pixels seen, their grey levels spread wider (a floor spans a few).
    preview = np.asarray(Image.open(tmp_path / "preview.png"))
    assert np.array_equal(preview > 0, image > 0)
    assert preview[image > 0].std() > 2 * image[image > 0].std()
    y = (tmp_path / "floor.yaml").read_text()
    assert re.search(r"^image: floor.png$", y, re.M)
    assert float(re.search(r"^resolution: (\S+)$", y, re.M).group(1)) == info.resolution == 0.002
    ox, oy, yaw = (float(v) for v in re.search(r"^origin: \[([^,]+), ([^,]+), ([^\]]+)\]$", y, re.M).groups())
    assert (ox, oy, yaw) == (info.origin[0], info.origin[1], 0.0)
    # Every camera foot point (the robot pose applied to the camera's x, y) lies under the image,
    # and the image is no larger than the footprints need: the camera sees at most 4 heights away.
    foot = np.stack([p[:, 0] + np.cos(p[:, 2]) * e.x - np.sin(p[:, 2]) * e.y,
                     p[:, 1] + np.sin(p[:, 2]) * e.x + np.cos(p[:, 2]) * e.y], axis=1)
    col = (foot[:, 0] - ox) / info.resolution
    row = info.height - (foot[:, 1] - oy) / info.resolution
    assert (col > 0).all() and (col < info.width).all() and (row > 0).all() and (row < info.height).all()
    reach = 4 * e.z / info.resolution + 2
    assert info.width <= np.ptp(col) + 2 * reach and info.height <= np.ptp(row) + 2 * reach


def test_mosaic_bad_input(context, drive):
    with planarvo.Dataset(drive) as ds:
        t, p = _truth(ds)
        e = ds.info.extrinsics_gt
        moved = t.copy()
        moved[3] += 0.01
        with pytest.raises(planarvo.Error) as err:
            planarvo.build_mosaic(context, ds, e, moved, p)
        assert err.value.status == planarvo.Status.INVALID_INPUT
        with pytest.raises(planarvo.Error) as err:
            planarvo.build_mosaic(context, ds, e, t[:0], p[:0])
        assert err.value.status == planarvo.Status.INVALID_INPUT
        with pytest.raises(planarvo.Error) as err:
            planarvo.build_mosaic(context, ds, e, t, p, resolution=1e-6)
        assert err.value.status == planarvo.Status.INVALID_INPUT
        with pytest.raises(ValueError):
            planarvo.build_mosaic(context, ds, e, t[:-1], p)
        with pytest.raises(ValueError):
            planarvo.build_mosaic(context, ds, e, t, p, resolution=float("nan"))
        with pytest.raises(planarvo.Error) as err:
            planarvo.build_mosaic(context, ds, e, t, p, progress=lambda f, s: True)
        assert err.value.status == planarvo.Status.CANCELLED
        # Millimetres for metres (issue 25): refused as a ValueError naming the mistake, unless accepted.
        mm = planarvo.Extrinsics(e.x * 1e3, e.y * 1e3, e.z * 1e3, e.roll, e.pitch, e.yaw)
        with pytest.raises(ValueError) as err:
            planarvo.build_mosaic(context, ds, mm, t, p, resolution=0.01)
        assert err.value.status == planarvo.Status.INVALID_ARGUMENT and "millimetres" in err.value.message
        # A camera on a 6 m mast: unusual (over 5 m), accepted when said so.
        mast = planarvo.Extrinsics(e.x, e.y, 6.0, e.roll, e.pitch, e.yaw)
        with pytest.raises(ValueError):
            planarvo.build_mosaic(context, ds, mast, t, p, resolution=0.05)
        m = planarvo.build_mosaic(context, ds, mast, t, p, resolution=0.05, accept_unusual_extrinsics=True)
        assert m.info.frames_used > 0
