"""inertialab.noise.spectral: Frequency and time-frequency views of a record: Welch
spectra and CWT scalograms, the Mallat wavelet view, empirical mode decomposition, and
spectral lines with their Allan variance.

Modules: emd, lines, spectra, wavelet.
"""

__all__: list[str] = []
