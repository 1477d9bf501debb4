"""The scalogram drawn as one image over log10(f) (the quad mesh of
pcolormesh was ~0.2 s of the report) puts each cell's colour at its time and frequency."""

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest

from inertialab.report.figures.vibration import _log_frequency_image


@pytest.mark.parametrize("descending", [True, False])
def test_each_cell_has_its_colour_at_its_frequency(descending):
    freq = np.geomspace(100.0, 0.05, 12)
    if not descending:
        freq = freq[::-1]
    z = np.random.default_rng(3).uniform(size=(freq.size, 30))
    fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
    _log_frequency_image(ax, z, freq, cmap="viridis", vmin=0, vmax=1)
    fig.canvas.draw()
    rgb = np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(int)
    h = rgb.shape[0]
    want = (np.asarray(matplotlib.colormaps["viridis"](z))[..., :3] * 255).round()
    for i, f in enumerate(freq):  # the y axis is log10(f): decade ticks name it
        for j in range(z.shape[1]):
            x, y = ax.transData.transform((j, np.log10(f)))
            got = rgb[h - 1 - int(round(y)), int(round(x))]
            assert np.abs(got - want[i, j]).max() <= 2, (i, j)
    ticks = dict(zip(ax.get_yticks(), (t.get_text() for t in ax.get_yticklabels())))
    assert ticks[-1.0] == "10⁻¹" and ticks[2.0] == "10²"
    plt.close(fig)


def test_other_grids_fall_back_to_the_mesh():
    freq = np.array([1.0, 2.0, 5.0, 7.0])
    fig, ax = plt.subplots()
    im = _log_frequency_image(ax, np.zeros((4, 5)), freq)
    assert ax.get_yscale() == "log" and type(im).__name__ == "QuadMesh"
    plt.close(fig)
