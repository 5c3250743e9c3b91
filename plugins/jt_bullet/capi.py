"""PyBullet's C API, called from compiled code on the client a ``pybullet.connect`` opened.

PyBullet's Python module is a thin layer over Bullet's C API (``b3SubmitClientCommandAndWaitStatus``,
``b3RequestActualStateCommandInit`` ...), which its shared library exports. The Python layer costs
most of a 600 Hz substep (building tuples and lists of floats for every joint); the same calls made
from a numba loop (``jt_bullet.fastloop``) cost a few microseconds. They need the C handle of the
client a Python ``connect`` returned: PyBullet keeps it in its static array ``sPhysicsClients1``,
which this module finds through the shared library's ELF symbol table. The handle is checked
(it must answer ``b3CanSubmitCommand`` and count the client's bodies as ``pybullet.getNumBodies``
does) before anything uses it; where any of this is missing, ``handle`` says why and the simulator
keeps its Python loop.

Every function is declared with 64-bit integers for its pointers (numba passes ``arr.ctypes.data``
and handles as ``int64``; the x86-64 and AArch64 ABIs pass both in the same registers).
"""

from __future__ import annotations

import ctypes
import functools
import struct
from typing import Any

I64, I32, F64 = ctypes.c_int64, ctypes.c_int, ctypes.c_double

#: the C functions the compiled loop calls: name -> (result, argument types)
PROTOTYPES: dict[str, tuple[Any, tuple[Any, ...]]] = {
    "b3SubmitClientCommandAndWaitStatus": (I64, (I64, I64)),
    "b3GetStatusType": (I32, (I64,)),
    "b3InitStepSimulationCommand": (I64, (I64,)),
    "b3RequestActualStateCommandInit": (I64, (I64, I32)),
    "b3GetStatusActualState": (I32, (I64, I64, I64, I64, I64, I64, I64, I64)),
    "b3JointControlCommandInit2": (I64, (I64, I32, I32)),
    "b3JointControlSetDesiredForceTorqueMultiDof": (I32, (I64, I32, I64, I32)),
    "b3InitRequestContactPointInformation": (I64, (I64,)),
    "b3SetContactFilterBodyA": (None, (I64, I32)),
    "b3GetContactPointInformation": (None, (I64, I64)),
    "b3InitClosestDistanceQuery": (I64, (I64,)),
    "b3SetClosestDistanceFilterBodyA": (None, (I64, I32)),
    "b3SetClosestDistanceFilterBodyB": (None, (I64, I32)),
    "b3SetClosestDistanceThreshold": (None, (I64, F64)),
    "b3CanSubmitCommand": (I32, (I64,)),
    "b3GetNumBodies": (I32, (I64,)),
    "b3GetLinkState": (I32, (I64, I64, I32, I64)),
    "b3RequestActualStateCommandComputeForwardKinematics": (I32, (I64, I32)),
    "b3RequestActualStateCommandComputeLinkVelocity": (I32, (I64, I32)),
}

#: EnumSharedMemoryServerStatus values (Bullet's SharedMemoryPublic.h); ``handle`` confirms the
#: state one on the live client before the loop relies on it
CMD_ACTUAL_STATE_UPDATE_COMPLETED = 21
CMD_CONTACT_POINT_INFORMATION_COMPLETED = 39
CONTROL_MODE_TORQUE = 1


class ContactPoint(ctypes.Structure):
    """``struct b3ContactPointData`` (SharedMemoryPublic.h): one contact or closest point."""

    _fields_ = [("flags", I32), ("body_a", I32), ("body_b", I32), ("link_a", I32), ("link_b", I32),
                ("position_a", F64 * 3), ("position_b", F64 * 3), ("normal_b", F64 * 3),
                ("distance", F64), ("normal_force", F64), ("friction1", F64), ("friction2", F64),
                ("friction_dir1", F64 * 3), ("friction_dir2", F64 * 3)]


#: int32 offsets of the fields the loop reads, and the struct's size in int32 words
POINT_WORDS = ctypes.sizeof(ContactPoint) // 4
POINT_BODY_B = ContactPoint.body_b.offset // 4
POINT_LINK_A = ContactPoint.link_a.offset // 4


def elf_symbols(path: str, names: set[str]) -> dict[str, int]:
    """Values of the named symbols in an ELF64 little-endian file's ``.symtab`` / ``.dynsym``.

    Args:
        path: the shared library.
        names: symbol names wanted.

    Returns:
        ``{name: st_value}`` for those found with a non-zero value (missing ones are left out).
    """
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
        return {}
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    sections = [struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize) for i in range(shnum)]
    out: dict[str, int] = {}
    for sec in sections:
        if sec[1] not in (2, 11):  # SHT_SYMTAB, SHT_DYNSYM
            continue
        strtab = sections[sec[6]]
        s0, s1 = strtab[4], strtab[4] + strtab[5]
        wanted = {}
        for name in names - out.keys():  # string-table offsets of the wanted names
            key = b"\0" + name.encode() + b"\0"
            at = data.find(key, s0, s1)
            while at >= 0:
                wanted[at + 1 - s0] = name
                at = data.find(key, at + 1, s1)
        if not wanted:
            continue
        for st_name, _info, _other, _shndx, value, _size in struct.iter_unpack(
                "<IBBHQQ", data[sec[4]:sec[4] + sec[5]]):
            if st_name in wanted and value:
                out[wanted[st_name]] = value
    return out


@functools.lru_cache(maxsize=1)
def library() -> tuple[Any, dict[str, Any], int]:
    """PyBullet's shared library, its C functions (typed as ``PROTOTYPES``) and the address of
    its ``sPhysicsClients1`` array (0 when the symbol table lacks it)."""
    import pybullet

    lib = ctypes.CDLL(pybullet.__file__)
    funcs = {}
    for name, (res, args) in PROTOTYPES.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = res, list(args)
        funcs[name] = fn
    syms = elf_symbols(pybullet.__file__, {"sPhysicsClients1", "b3GetStatusType"})
    if "sPhysicsClients1" not in syms or "b3GetStatusType" not in syms:
        return lib, funcs, 0
    base = ctypes.cast(lib.b3GetStatusType, ctypes.c_void_p).value - syms["b3GetStatusType"]
    return lib, funcs, base + syms["sPhysicsClients1"]


def handle(client: int, body: int) -> tuple[int, str]:
    """The C handle of PyBullet client ``client``, checked on ``body``.

    Args:
        client: a ``pybullet.connect`` id.
        body: a body of that client whose state the loop will read.

    Returns:
        ``(handle, "")``, or ``(0, reason)`` when the handle cannot be found or does not answer as
        that client (a PyBullet build without its symbol table, another layout).
    """
    import pybullet

    try:
        _lib, f, array = library()
    except (OSError, AttributeError) as exc:
        return 0, f"PyBullet's C API is not reachable ({exc})"
    if not array:
        return 0, "PyBullet's shared library has no symbol table entry for its client array"
    if not 0 <= int(client) < 1024:
        return 0, f"client id {client} out of range"
    h = ctypes.c_void_p.from_address(array + 8 * int(client)).value or 0
    if not h or f["b3CanSubmitCommand"](h) != 1:
        return 0, "the client's C handle does not accept commands"
    if f["b3GetNumBodies"](h) != pybullet.getNumBodies(physicsClientId=client):
        return 0, "the C handle found is not this client's"
    status = f["b3SubmitClientCommandAndWaitStatus"](h, f["b3RequestActualStateCommandInit"](h, body))
    if f["b3GetStatusType"](status) != CMD_ACTUAL_STATE_UPDATE_COMPLETED:
        return 0, "the C API's status codes differ from the ones this module knows"
    return h, ""
