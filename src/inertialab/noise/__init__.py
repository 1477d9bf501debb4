"""inertialab.noise: Allan family, noise terms, wavelet multiscale views, spectra, EMD.

Import the functions from their modules (``inertialab.noise.wavelet`` ...); this package
keeps no import-time side effects.
"""
