"""A control step's 600 Hz substeps in one numba loop, through PyBullet's C API.

Each substep does what ``BulletSimulator``'s Python loop does, in the same order and on the same
doubles: SPD torques by the backend's kernel (MABA, DF, SF or PCG from ``toolkit.dynamics``),
clipped to the torque limits, applied with one torque command, one ``stepSimulation``, the state
read back, the NaN / explosion check, then at every ``check_every``-th substep the episode's
``Watch``: the recorded quantities, the contacts of the character and the first contact rule that
fires (with the closest-point query of a ``clear_of`` rule), the first touches, the time limit.
The same seed gives the same trajectory, bit for bit, as the Python loop
(``tests/plugins/jt_bullet/test_fastloop.py``).

The C functions' addresses come in as an array (``funcs()``), called through ``_c_call``
intrinsics, so the compiled loop can be cached on disk and its dispatch stays cheap.
"""

from __future__ import annotations

import ctypes

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic

from jt_bullet import capi
from toolkit.dynamics.com import com_kernel
from toolkit.dynamics.maba import maba_kernel
from toolkit.dynamics.model import V_TAU
from toolkit.dynamics.spd import spd_system_kernel

#: failure codes of ``substeps`` (``iout[1]``)
OK, NAN_STATE, FAST, FAR, BAD_TORQUE = 0, 1, 2, 3, 4
#: SPD kernels (``method``): MABA, or the explicit system by DF / SF / PCG (spd_system_kernel's modes);
#: SERVO: no torques at all (``spd=servo``: PyBullet's constraint motors, armed before the loop)
MABA, DF, SF, PCG, SERVO = -1, 0, 1, 2, 3
#: ``iout`` entries: substeps done, failure code, fired rule (-1: none, -2: the time limit), records, PCG iterations
I_DONE, I_FAIL, I_RULE, I_REC, I_ITS = range(5)
#: ``timers`` entries (seconds): SPD, physics, state/torque I/O, whole substeps
T_SPD, T_PHYS, T_IO, T_SUB = range(4)
capi_point_words = capi.POINT_WORDS
_BODY_B, _LINK_A = capi.POINT_BODY_B, capi.POINT_LINK_A


def _c_call(restype, *argtypes):
    """A numba intrinsic ``call(address, (args...))`` calling the C function at ``address`` with
    the signature ``restype(*argtypes)``: addresses arrive at run time (``FUNCS``' array), so the
    loop that calls them can be cached on disk (ctypes function objects as arguments cost ~20 µs
    of dispatch per call; as globals they would be frozen into the cache)."""

    @intrinsic
    def call(typingctx, address, args):
        def codegen(context, builder, signature, llargs):
            ptr, tup = llargs
            ret = ir.VoidType() if restype is types.void else context.get_value_type(restype)
            fnty = ir.FunctionType(ret, [context.get_value_type(t) for t in argtypes])
            fn = builder.inttoptr(ptr, fnty.as_pointer())
            vals = [context.cast(builder, builder.extract_value(tup, i), signature.args[1][i], t)
                    for i, t in enumerate(argtypes)]
            out = builder.call(fn, vals)
            return context.get_dummy_value() if restype is types.void else out

        return (types.none if restype is types.void else restype)(address, args), codegen

    return call


_i64, _i32, _f64, _void = types.int64, types.int32, types.float64, types.void
#: the C functions the loop calls, in ``FUNCS`` order: (name, numba intrinsic)
_C = (
    ("b3SubmitClientCommandAndWaitStatus", _c_call(_i64, _i64, _i64)),
    ("b3GetStatusType", _c_call(_i32, _i64)),
    ("b3InitStepSimulationCommand", _c_call(_i64, _i64)),
    ("b3RequestActualStateCommandInit", _c_call(_i64, _i64, _i32)),
    ("b3GetStatusActualState", _c_call(_i32, *[_i64] * 8)),
    ("b3JointControlCommandInit2", _c_call(_i64, _i64, _i32, _i32)),
    ("b3JointControlSetDesiredForceTorqueMultiDof", _c_call(_i32, _i64, _i32, _i64, _i32)),
    ("b3InitRequestContactPointInformation", _c_call(_i64, _i64)),
    ("b3SetContactFilterBodyA", _c_call(_void, _i64, _i32)),
    ("b3GetContactPointInformation", _c_call(_void, _i64, _i64)),
    ("b3InitClosestDistanceQuery", _c_call(_i64, _i64)),
    ("b3SetClosestDistanceFilterBodyA", _c_call(_void, _i64, _i32)),
    ("b3SetClosestDistanceFilterBodyB", _c_call(_void, _i64, _i32)),
    ("b3SetClosestDistanceThreshold", _c_call(_void, _i64, _f64)),
    ("memcpy", _c_call(_i64, _i64, _i64, _i64)),
    ("clock_gettime", _c_call(_i32, _i32, _i64)),
    ("b3GetLinkState", _c_call(_i32, _i64, _i64, _i32, _i64)),
    ("b3RequestActualStateCommandComputeForwardKinematics", _c_call(_i32, _i64, _i32)),
    ("b3RequestActualStateCommandComputeLinkVelocity", _c_call(_i32, _i64, _i32)),
)
(_submit, _status_type, _step_init, _state_init, _actual_state, _control_init, _set_forces,
 _contact_init, _contact_filter_a, _contact_info, _closest_init, _closest_a, _closest_b,
 _closest_threshold, _memcpy, _clock, _link_state, _with_fk, _with_vel) = (c for _n, c in _C)
(SUBMIT, STATUS_TYPE, STEP_INIT, STATE_INIT, ACTUAL_STATE, CONTROL_INIT, SET_FORCES, CONTACT_INIT,
 CONTACT_FILTER_A, CONTACT_INFO, CLOSEST_INIT, CLOSEST_A, CLOSEST_B, CLOSEST_THRESHOLD, MEMCPY,
 CLOCK, LINK_STATE, WITH_FK, WITH_VEL) = range(len(_C))
LINK_STATE_DOUBLES = 33  #: sizeof(struct b3LinkState) / 8 (SharedMemoryPublic.h)


def funcs() -> np.ndarray:
    """The addresses ``(16,)`` int64 of ``_C``'s functions in this process (PyBullet's C API, libc)."""
    _lib, f, _arr = capi.library()
    libc = ctypes.CDLL(None)
    out = []
    for name, _call in _C:
        fn = f[name] if name in f else getattr(libc, name)
        out.append(ctypes.cast(fn, ctypes.c_void_p).value)
    return np.array(out, dtype=np.int64)


@njit(cache=True)
def _now(fns, ts) -> float:
    _clock(fns[CLOCK], (1, ts.ctypes.data))  # CLOCK_MONOTONIC
    return ts[0] + 1e-9 * ts[1]


@njit(cache=True)
def read_state(fns, h, body, holder, bq, bu, qmap, umap, q, qd) -> None:
    """Request the body's state and gather it into ``q`` ``(n_q,)``, ``qd`` ``(n_v,)`` (jt layout)."""
    status = _submit(fns[SUBMIT], (h, _state_init(fns[STATE_INIT], (h, body))))
    hp = holder.ctypes.data
    _actual_state(fns[ACTUAL_STATE], (status, 0, 0, 0, 0, hp, hp + 8, 0))
    _memcpy(fns[MEMCPY], (bq.ctypes.data, holder[0], bq.size * 8))
    _memcpy(fns[MEMCPY], (bu.ctypes.data, holder[1], bu.size * 8))
    for i in range(q.shape[0]):
        q[i] = bq[qmap[i]]
    for i in range(qd.shape[0]):
        qd[i] = bu[umap[i]]


@njit(cache=True)
def link_states(fns, h, body, holder, ls, pos, orn) -> None:
    """World centre-of-mass positions ``pos`` ``(n_links + 1, 3)`` and orientations ``orn``
    ``(n_links + 1, 4)`` of the base and every link, as PyBullet's getBasePositionAndOrientation and
    getLinkStates report them (the same request and the same fields)."""
    status = _submit(fns[SUBMIT], (h, _state_init(fns[STATE_INIT], (h, body))))
    hp = holder.ctypes.data
    _actual_state(fns[ACTUAL_STATE], (status, 0, 0, 0, 0, hp, 0, 0))
    _memcpy(fns[MEMCPY], (ls.ctypes.data, holder[0], 7 * 8))
    for i in range(3):
        pos[0, i] = ls[i]
    for i in range(4):
        orn[0, i] = ls[3 + i]
    for link in range(pos.shape[0] - 1):
        _link_state(fns[LINK_STATE], (h, status, link, ls.ctypes.data))
        for i in range(3):
            pos[link + 1, i] = ls[i]
        for i in range(4):
            orn[link + 1, i] = ls[3 + i]


@njit(cache=True)
def link_velocities(fns, h, body, holder, ls, lin, ang) -> None:
    """World linear ``lin`` and angular ``ang`` velocities ``(n_links + 1, 3)`` of the base and every
    link's centre of mass, as PyBullet's getBaseVelocity and getLinkStates(computeLinkVelocity=1)
    report them (the same request and the same fields: ``m_worldLinearVelocity`` /
    ``m_worldAngularVelocity``, from the current joint velocities)."""
    cmd = _state_init(fns[STATE_INIT], (h, body))
    _with_vel(fns[WITH_VEL], (cmd, 1))
    status = _submit(fns[SUBMIT], (h, cmd))
    hp = holder.ctypes.data
    _actual_state(fns[ACTUAL_STATE], (status, 0, 0, 0, 0, 0, hp, 0))
    _memcpy(fns[MEMCPY], (ls.ctypes.data, holder[0], 6 * 8))  # the base's qdot: v, w (world)
    for i in range(3):
        lin[0, i] = ls[i]
        ang[0, i] = ls[3 + i]
    for link in range(lin.shape[0] - 1):
        _link_state(fns[LINK_STATE], (h, status, link, ls.ctypes.data))
        for i in range(3):
            lin[link + 1, i] = ls[21 + i]  # m_worldLinearVelocity
            ang[link + 1, i] = ls[24 + i]  # m_worldAngularVelocity


@njit(cache=True)
def link_frames(fns, h, body, holder, ls, links, pos, orn) -> None:
    """World positions ``pos`` ``(n, 3)`` and orientations ``orn`` ``(n, 4)`` of the URDF frames of
    ``links`` ``(n,)`` (-1: the base) by forward kinematics of the current state, as PyBullet's
    getLinkState(computeForwardKinematics=True) and getBasePositionAndOrientation report them."""
    cmd = _state_init(fns[STATE_INIT], (h, body))
    _with_fk(fns[WITH_FK], (cmd, 1))
    status = _submit(fns[SUBMIT], (h, cmd))
    hp = holder.ctypes.data
    for k in range(links.shape[0]):
        if links[k] < 0:
            _actual_state(fns[ACTUAL_STATE], (status, 0, 0, 0, 0, hp, 0, 0))
            _memcpy(fns[MEMCPY], (ls.ctypes.data, holder[0], 7 * 8))
            for i in range(3):
                pos[k, i] = ls[i]
            for i in range(4):
                orn[k, i] = ls[3 + i]
        else:
            _link_state(fns[LINK_STATE], (h, status, links[k], ls.ctypes.data))
            for i in range(3):
                pos[k, i] = ls[14 + i]  # m_worldLinkFramePosition
            for i in range(4):
                orn[k, i] = ls[17 + i]  # m_worldLinkFrameOrientation


@njit(cache=True)
def _contacts(fns, h, body, cinfo, cinfo32, pts, ok_status) -> int:
    """Contact points of ``body`` now into ``pts`` (int32 words of b3ContactPointData); their count."""
    cmd = _contact_init(fns[CONTACT_INIT], (h,))
    _contact_filter_a(fns[CONTACT_FILTER_A], (cmd, body))
    status = _submit(fns[SUBMIT], (h, cmd))
    if _status_type(fns[STATUS_TYPE], (status,)) != ok_status:
        return 0
    _contact_info(fns[CONTACT_INFO], (h, cinfo.ctypes.data))
    n = cinfo32[0]
    cap = pts.shape[0] // capi_point_words
    if n > cap:
        n = cap
    _memcpy(fns[MEMCPY], (pts.ctypes.data, cinfo[1], n * capi_point_words * 4))
    return n


@njit(cache=True)
def _near(fns, h, body, other, margin, cinfo, cinfo32, ok_status) -> bool:
    """Any part of ``body`` within ``margin`` m of ``other`` (PyBullet's getClosestPoints)."""
    if other < 0:
        return False
    cmd = _closest_init(fns[CLOSEST_INIT], (h,))
    _closest_a(fns[CLOSEST_A], (cmd, body))
    _closest_b(fns[CLOSEST_B], (cmd, other))
    _closest_threshold(fns[CLOSEST_THRESHOLD], (cmd, margin))
    status = _submit(fns[SUBMIT], (h, cmd))
    if _status_type(fns[STATUS_TYPE], (status,)) != ok_status:
        return False
    _contact_info(fns[CONTACT_INFO], (h, cinfo.ctypes.data))
    return cinfo32[0] > 0


@njit(cache=True)
def substeps(api, maps, bufs, spd, com, watch, records, n, t, control, checks, q, qd, touched,
             touched_any, out) -> None:
    """Run up to ``n`` substeps (see the module docstring); results in ``q``, ``qd``, ``wv[V_TAU]``
    (the last clipped torques), ``iout``, ``fout`` (``[time, max |qd|]``), ``touched`` and the
    ``rec_*`` rows, timings added to ``timers``.

    The arrays come grouped in plain tuples (``CompiledSteps`` builds those of a body once, those
    of a ``Watch`` once per watch): numba's dispatcher types a tuple of arrays as fast as the same
    arrays given flat (a ``NamedTuple`` would take twice as long), and unpacking them here costs
    nothing in the compiled code, which is the same loop on the same doubles.

    Args:
        api: ``(fns, h, body, ok_contact)``: the C functions' addresses (``funcs()``), the physics
            client's handle, the body's unique id, and the status of a completed contact query.
        maps: ``(qmap, umap, j_uindex, j_start, j_count)`` int64: PyBullet's q / u index of each jt
            coordinate, and per joint its u index, first jt dof and dof count (torque commands).
        bufs: ``(bq, bu, holder, ts, cinfo, cinfo32, pts)``: PyBullet's q and u, the state's
            pointers, a ``timespec``, the contact info (int64 and its int32 view), contact points.
        spd: ``(method, mi, mf, lam, grav, wb, wv, sc, H, A, zeros, tol, max_iter)``: the SPD kernel
            (``MABA``, ``DF``, ``SF``, ``PCG``, ``SERVO``), the model's tables, dof parents and
            gravity, the kernel's workspaces, zeros ``(n_v,)``, PCG's tolerance and iteration cap.
        com: ``(c_mass, c_com, c_world, c_wb, c_sc)``: ``com_kernel``'s tables and workspaces.
        watch: ``(every, active, time_limit, rule_body, rule_mask, rule_fail, rule_clear,
            rule_margin, touch_body)``: check every ``every``-th substep (only if ``active``), end
            at ``time_limit``; per contact rule its other body, character links ``(n_links + 1,)``,
            whether it fails, the body to be clear of (-1: none) and by what margin; the bodies
            whose first touches are wanted.
        records: ``(rec_flags, rec_time, rec_com, rec_root)``: which of time, CoM, root to record,
            and their rows.
        n: substeps to run at most.
        t: the simulator's time at the start (s).
        control: ``(qt, qdt, kp, kd, lim, dt)``: SPD targets, gains, torque limits, substep (s).
        checks: ``(explode_speed, explode_d2, fixed_base)``: the explosion check's bounds.
        q: ``(n_q,)``, filled with the state at the end.
        qd: ``(n_v,)``, likewise.
        touched: ``(n_touch, n_links + 1)`` bool, the links that touched each ``touch_body``.
        touched_any: ``(n_touch,)`` bool, whether any did.
        out: ``(timers, iout, fout)``: timings (``T_*``), results (``I_*``), time and max ``|qd|``.
    """
    fns, h, body, ok_contact = api
    qmap, umap, j_uindex, j_start, j_count = maps
    bq, bu, holder, ts, cinfo, cinfo32, pts = bufs
    method, mi, mf, lam, grav, wb, wv, sc, H, A, zeros, tol, max_iter = spd
    c_mass, c_com, c_world, c_wb, c_sc = com
    every, active, time_limit, rule_body, rule_mask, rule_fail, rule_clear, rule_margin, touch_body = watch
    rec_flags, rec_time, rec_com, rec_root = records
    qt, qdt, kp, kd, lim, dt = control
    explode_speed, explode_d2, fixed_base = checks
    timers, iout, fout = out
    tau = wv[V_TAU]
    nv = qd.shape[0]
    nr = rule_body.shape[0]
    nt = touch_body.shape[0]
    read_state(fns, h, body, holder, bq, bu, qmap, umap, q, qd)
    done = 0
    fail = OK
    fired = -1
    n_rec = 0
    its = 0
    vmax = 0.0
    for k in range(n):
        t0 = _now(fns, ts)
        if method == SERVO:  # the motors act inside the step
            t1 = t0
        else:
            if method == MABA:
                maba_kernel(mi, mf, q, qd, qt, qdt, kp, kd, dt, zeros, grav, wb, wv, sc)
            else:
                its = spd_system_kernel(mi, mf, lam, q, qd, qt, qdt, kp, kd, dt, zeros, grav, wb, wv,
                                        sc, H, A, method, tol, max_iter)
            t1 = _now(fns, ts)
            s = 0.0
            for i in range(nv):
                x = tau[i]
                if x > lim[i]:  # np.minimum / np.maximum keep a NaN, as these comparisons do
                    x = lim[i]
                if x < -lim[i]:
                    x = -lim[i]
                tau[i] = x
                s += x
            if not np.isfinite(s):
                fail = BAD_TORQUE
                break
            cmd = _control_init(fns[CONTROL_INIT], (h, body, 1))  # CONTROL_MODE_TORQUE
            for j in range(j_uindex.shape[0]):
                _set_forces(fns[SET_FORCES], (cmd, j_uindex[j], tau.ctypes.data + 8 * j_start[j], j_count[j]))
            _submit(fns[SUBMIT], (h, cmd))
        t2 = _now(fns, ts)
        _submit(fns[SUBMIT], (h, _step_init(fns[STEP_INIT], (h,))))
        t3 = _now(fns, ts)
        read_state(fns, h, body, holder, bq, bu, qmap, umap, q, qd)
        t4 = _now(fns, ts)
        timers[T_SPD] += t1 - t0
        timers[T_PHYS] += t3 - t2
        timers[T_IO] += (t2 - t1) + (t4 - t3)
        timers[T_SUB] += t4 - t0
        done += 1
        t += dt
        # the NaN / explosion check (BulletSimulator._check on BulletBody.read's floats)
        sq = 0.0
        for i in range(q.shape[0]):
            sq += q[i]
        sv = 0.0
        vmax = 0.0
        for i in range(nv):
            sv += qd[i]
            a = abs(qd[i])
            if a > vmax:
                vmax = a
        if not (np.isfinite(sq + sv) and vmax <= explode_speed and (
                fixed_base or q[0] * q[0] + q[1] * q[1] + q[2] * q[2] <= explode_d2)):
            finite = True
            for i in range(q.shape[0]):
                if not np.isfinite(q[i]):
                    finite = False
            for i in range(nv):
                if not np.isfinite(qd[i]):
                    finite = False
            fail = NAN_STATE if not finite else (FAST if vmax > explode_speed else FAR)
            break
        if not active or ((k + 1) % every != 0 and k + 1 < n):
            continue
        # the Watch (jt_bullet.watch.Checker.after_substep)
        if rec_flags[0]:
            rec_time[n_rec] = t
        if rec_flags[1]:
            com_kernel(mi, mf, q, c_wb, c_sc, c_mass, c_com, c_world, rec_com[n_rec])
        if rec_flags[2]:
            for i in range(7):
                rec_root[n_rec, i] = q[i]
        if rec_flags[0] or rec_flags[1] or rec_flags[2]:
            n_rec += 1
        npts = 0
        if nr > 0 or nt > 0:
            npts = _contacts(fns, h, body, cinfo, cinfo32, pts, ok_contact)
        hit_rule = -1
        for r in range(nr):
            hit = False
            for p in range(npts):
                if pts[p * capi_point_words + _BODY_B] == rule_body[r] and \
                        rule_mask[r, pts[p * capi_point_words + _LINK_A] + 1]:
                    hit = True
                    break
            if hit and (rule_fail[r] or rule_clear[r] < 0
                        or not _near(fns, h, body, rule_clear[r], rule_margin[r], cinfo, cinfo32,
                                     ok_contact)):
                hit_rule = r
                break
        if hit_rule >= 0 and rule_fail[hit_rule]:
            fired = hit_rule
            break
        for b in range(nt):
            if not touched_any[b]:
                for p in range(npts):
                    if pts[p * capi_point_words + _BODY_B] == touch_body[b]:
                        touched[b, pts[p * capi_point_words + _LINK_A] + 1] = True
                        touched_any[b] = True
        if hit_rule >= 0:
            fired = hit_rule
            break
        if t >= time_limit - 1e-9:
            fired = -2
            break
    iout[I_DONE] = done
    iout[I_FAIL] = fail
    iout[I_RULE] = fired
    iout[I_REC] = n_rec
    iout[I_ITS] = its
    fout[0] = t
    fout[1] = vmax
