"""The result of cf.replay, and reading cfreplay's trajectory files into arrays."""

from __future__ import annotations

import os as _os
from typing import TYPE_CHECKING, Any, Sequence

import numpy as _np

from . import _cf

if TYPE_CHECKING:
    import os

    import numpy.typing as npt


class ReplayResult:
    """One row per servo tick of cf.replay, as numpy arrays named like cf::HapticResult.

    t_s (N,)                seconds
    cf (N,) int32           the CF's id, -1 for none
    pcs (N,) str            its PCs 'type:a:b;...' (when no CF fits: the contacts rendered)
    motion (N,) str         'MT1' .. 'MT5', 'MT2.a/b/c', 'none'
    status (N,) str         'no_contact', 'ok', 'no_fitting_cf', 'unlisted_transition'
    identification (N,) str the identifier's status ('matched-previous', ...)
    num_detected (N,) int32 candidate PCs detected
    F_W, M_W (N, 3)         the rendered force (N) and moment (N mm) in the world frame: the
                            coupling to the proxy, the contact at the proxy and gravity
    F_A, M_A (N, 3)         the same in A's frame
    F_contact_W, M_contact_W (N, 3)  what B exerts on A (eqs. (1)-(8) plus the proxy's
                            constraint forces); F_gravity_W (N, 3) the weight
    proxy_p (N, 3), proxy_q (N, 4)   the proxy pose A was rendered at (mm; w, x, y, z), the
                            device pose when the proxy is off or nothing held it back
    conservative (N,) bool  rendered with the conservative laws
    dof (N,) int32          freedoms the force model computed (6 when it did not)
    regimes (N,) str        per-PC friction regimes, as cfreplay's regimes column

    ``t`` is ``t_s``; ``to_csv()`` gives cfreplay's output text, byte for byte.
    """

    _FIELDS = ("t_s", "cf", "pcs", "motion", "status", "identification", "num_detected", "F_W", "M_W",
               "F_A", "M_A", "F_contact_W", "M_contact_W", "F_gravity_W", "proxy_p", "proxy_q", "conservative",
               "dof", "regimes")

    t_s: npt.NDArray[_np.float64]
    cf: npt.NDArray[_np.int32]
    pcs: npt.NDArray[_np.str_]
    motion: npt.NDArray[_np.str_]
    status: npt.NDArray[_np.str_]
    identification: npt.NDArray[_np.str_]
    num_detected: npt.NDArray[_np.int32]
    F_W: npt.NDArray[_np.float64]
    M_W: npt.NDArray[_np.float64]
    F_A: npt.NDArray[_np.float64]
    M_A: npt.NDArray[_np.float64]
    F_contact_W: npt.NDArray[_np.float64]
    M_contact_W: npt.NDArray[_np.float64]
    F_gravity_W: npt.NDArray[_np.float64]
    proxy_p: npt.NDArray[_np.float64]
    proxy_q: npt.NDArray[_np.float64]
    conservative: npt.NDArray[_np.bool_]
    dof: npt.NDArray[_np.int32]
    regimes: npt.NDArray[_np.str_]

    def __init__(self, d: dict[str, Any], inputs: Sequence[str] = ()) -> None:
        """From the arrays cf.replay and step_many return (d), and the files the CSV must
        never overwrite (inputs). Made by those calls, not by hand."""
        self._rows = d.pop("_rows")
        self._inputs = list(inputs)
        for name in self._FIELDS:
            v = d[name]
            setattr(self, name, _np.array(v, dtype=str) if isinstance(v, list) else v)

    @property
    def t(self) -> npt.NDArray[_np.float64]:
        return self.t_s

    def __len__(self) -> int:
        return len(self.t_s)

    def __repr__(self) -> str:
        n = len(self)
        contact = int((self.status != "no_contact").sum())
        return f"<cf.ReplayResult: {n} ticks, {contact} in contact, {len(set(self.cf[self.cf >= 0]))} CFs>"

    def to_csv(self, path: str | os.PathLike[str] | None = None) -> str:
        """cfreplay's CSV (header t,cf,pcs,motion,Fx,...,status,regimes), '.' decimals in any
        locale; written to path when given, as cfreplay writes: whole or not at all, never over
        the graph the result came from, never to a device, FIFO or directory (cf.Error)."""
        text: str = self._rows.csv()
        if path is not None:
            _cf._write_text(_os.fspath(path), text, self._inputs)
        return text


def read_trajectory(
        path: str | os.PathLike[str]) -> tuple[npt.NDArray[_np.float64], npt.NDArray[_np.float64],
                                               npt.NDArray[_np.float64]]:
    """Reads a cfreplay trajectory CSV (header t,tx,ty,tz,qw,qx,qy,qz; '#' lines and blank lines
    skipped) into (t (N,), p (N, 3), q (N, 4)) float64 arrays, ready for cf.replay. The reader
    is cfreplay's: a FIFO, device or directory is refused without blocking, and so is a row
    that is not a pose (a field not a finite number, a quaternion off unit norm, a time that
    does not increase), with cf.Error naming the file and line."""
    t, p, q = _cf._read_trajectory(_os.fspath(path))
    return t, p, q
