"""Curve descriptors and closed-form alignment for curve synthesis.

* :func:`resample`: ``M`` points equally spaced in arc length along a polyline (closed
  or open). An open arc is described by its there-and-back loop, so an oscillating
  linkage's arc and an open target compare like closed curves.
* :func:`fourier_descriptor`: magnitudes of the Fourier coefficients ``Z_k``
  (``k = +-1 .. +-n``) of the resampled points as complex numbers, divided by the norm
  of all of them: invariant to translation (``Z_0`` dropped), scale (the norm),
  rotation and starting point (both only turn the phases: ``Z_k -> Z_k e^{i(a + k s)}``).
  Reversing the direction or reflecting the curve swaps ``k`` and ``-k``; queries are
  made for both (C. T. Zahn and R. Z. Roskies, "Fourier descriptors for plane closed
  curves", *IEEE Transactions on Computers* C-21(3), 269-281, 1972).
* :func:`align`: the similarity (complex factor ``c``, translation) and the cyclic
  start shift that best map a candidate onto the target, in closed form for every
  shift at once: for centred curves ``z`` and ``w``, ``c = <z_s, w> / |z|^2`` and the
  residual ``|w|^2 - |<z_s, w>|^2 / |z|^2``, with ``<z_s, w>`` for all shifts ``s``
  one circular cross-correlation (FFT); mirror images and reversed direction are tried
  too (Umeyama-type least-squares similarity, S. Umeyama, "Least-squares estimation of
  transformation parameters between two point patterns", *IEEE Transactions on
  Pattern Analysis and Machine Intelligence* 13(4), 376-380, 1991).
"""

from __future__ import annotations

import numpy as np

__all__ = ["resample", "fourier_descriptor", "align", "Alignment", "N_HARMONICS", "N_RESAMPLE"]

N_HARMONICS = 10
N_RESAMPLE = 64


def _as_complex(points: np.ndarray) -> np.ndarray:
    p = np.asarray(points)
    return p if np.iscomplexobj(p) else p[..., 0] + 1j * p[..., 1]


def resample(points: np.ndarray, m: int = N_RESAMPLE, closed: bool = True) -> np.ndarray:
    """``m`` points (complex, ``(..., m)``) equally spaced in arc length.

    ``points``: ``(..., n, 2)`` real or ``(..., n)`` complex, no NaN. An open curve is
    traversed there and back.

    >>> z = resample(np.exp(2j * np.pi * np.arange(7) / 7), 4)
    >>> bool(np.allclose(np.abs(z), 1, atol=0.1))
    True
    """
    z = _as_complex(points)
    if not closed:
        z = np.concatenate([z, z[..., -2:0:-1]], axis=-1)
    zc = np.concatenate([z, z[..., :1]], axis=-1)
    seg = np.abs(np.diff(zc, axis=-1))
    s = np.concatenate([np.zeros(seg.shape[:-1] + (1,)), np.cumsum(seg, axis=-1)], axis=-1)
    total = s[..., -1:]
    total = np.where(total > 0, total, 1.0)
    u = np.arange(m) / m * total                                # (..., m)
    flat_s = s.reshape(-1, s.shape[-1])
    flat_u = u.reshape(-1, m)
    flat_z = zc.reshape(-1, zc.shape[-1])
    out = np.empty(flat_u.shape, complex)
    for i in range(len(flat_s)):
        out[i] = (np.interp(flat_u[i], flat_s[i], flat_z[i].real)
                  + 1j * np.interp(flat_u[i], flat_s[i], flat_z[i].imag))
    return out.reshape(u.shape)


def fourier_descriptor(z: np.ndarray, n: int = N_HARMONICS) -> np.ndarray:
    """Normalised Fourier magnitudes ``(..., 2n)`` of resampled curves ``(..., m)``:
    ``|Z_1| .. |Z_n|, |Z_-1| .. |Z_-n|`` over their norm (see the module doc).

    >>> w = np.exp(2j * np.pi * np.arange(64) / 64)
    >>> d1 = fourier_descriptor(w)
    >>> d2 = fourier_descriptor(3 * np.roll(w, 5) * np.exp(0.7j) + 2 - 1j)
    >>> bool(np.allclose(d1, d2)), round(float(d1[0]), 6)
    (True, 1.0)
    """
    Z = np.fft.fft(z, axis=-1)
    pos = np.abs(Z[..., 1:n + 1])
    neg = np.abs(Z[..., -1:-n - 1:-1])
    d = np.concatenate([pos, neg], axis=-1)
    norm = np.linalg.norm(d, axis=-1, keepdims=True)
    return d / np.where(norm > 0, norm, 1.0)


def swap_direction(desc: np.ndarray) -> np.ndarray:
    """The descriptor of the same curve run the other way (or mirrored)."""
    n = desc.shape[-1] // 2
    return np.concatenate([desc[..., n:], desc[..., :n]], axis=-1)


class Alignment:
    """Best similarity of candidates onto a target: ``w ~ c z' + t`` with ``z'`` the
    candidate (mirrored when ``mirror``, reversed when ``reverse``, then
    ``np.roll(z', shift)``); ``rms`` the residual per point (target units)."""

    def __init__(self, c, t, shift, mirror, reverse, rms):
        self.c, self.t, self.shift, self.mirror, self.reverse, self.rms = c, t, shift, mirror, reverse, rms

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Map real points ``(..., 2)`` of a candidate's frame to the target's."""
        z = _as_complex(points)
        if np.ndim(self.c):
            raise ValueError("apply one alignment at a time")
        if self.mirror:
            z = np.conj(z)
        w = self.c * z + self.t
        return np.stack([w.real, w.imag], axis=-1)


def align(candidates: np.ndarray, target: np.ndarray, mirror: bool = True) -> Alignment:
    """Closed-form similarity + start shift of resampled candidates ``(K, m)`` onto a
    resampled target ``(m,)`` (complex), trying both directions (and mirror images).

    >>> w = resample(np.array([[0, 0], [2, 0], [2, 1], [0, 1.0]]), 32)
    >>> z = (np.roll(w, 7) - 1) * (0.5 - 0.2j)
    >>> a = align(z[None], w)
    >>> fit = a.c[0] * np.roll(z, a.shift[0]) + a.t[0]
    >>> bool(a.rms[0] < 1e-6), bool(np.allclose(fit, w))
    (True, True)
    """
    Z = np.atleast_2d(candidates)
    w = np.asarray(target)
    m = w.shape[-1]
    wc = w - w.mean()
    best = None
    for mir in ((False, True) if mirror else (False,)):
        for rev in (False, True):
            z = np.conj(Z) if mir else Z
            if rev:
                z = z[:, ::-1]
            zm = z.mean(axis=1, keepdims=True)
            zc = z - zm
            nz = np.sum(np.abs(zc) ** 2, axis=1)
            # corr[s] = sum_j conj(zc[j]) wc[(j + s) % m]: w ~ c roll(z, s)
            corr = np.fft.ifft(np.conj(np.fft.fft(zc, axis=1)) * np.fft.fft(wc)[None, :], axis=1)
            s = np.argmax(np.abs(corr), axis=1)
            g = corr[np.arange(len(Z)), s]
            c = g / np.where(nz > 0, nz, 1.0)
            res = np.sum(np.abs(wc) ** 2) - np.abs(g) ** 2 / np.where(nz > 0, nz, 1.0)
            rms = np.sqrt(np.maximum(res, 0.0) / m)
            t = w.mean() - c * zm[:, 0]
            cand = (rms, c, t, s, np.full(len(Z), mir), np.full(len(Z), rev))
            if best is None:
                best = cand
            else:
                better = cand[0] < best[0]
                best = tuple(np.where(better, new, old) for new, old in zip(cand, best))
    rms, c, t, s, mir, rev = best
    return Alignment(c, t, s, mir, rev, rms)
