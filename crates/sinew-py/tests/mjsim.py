"""MuJoCo's side of the export checks: load an exported model, evaluate its static residual,
solve its equilibrium by Newton and measure its compliance, simulate it. Only MuJoCo's own
quantities enter (qfrc_passive, qfrc_actuator, qfrc_bias, ten_J, site poses): nothing from
Sinew but the file."""

import numpy as np
import mujoco


class Exported:
    """An exported model at its keyframe `exported`, with the load F0 of the file."""

    def __init__(self, xml: str):
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        mujoco.mj_resetDataKeyframe(self.model, self.data, 0)
        self.q0 = self.data.qpos.copy()
        adr = self.model.numeric_adr[mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_NUMERIC, "sinew_wrench")]
        self.f0 = self.model.numeric_data[adr:adr + 6].copy()
        self.tip = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, "tip")
        self.tip_body = self.model.site_bodyid[self.tip]
        mujoco.mj_forward(self.model, self.data)

    def at(self, q):
        """Positions, velocities zero, at `q` (mj_forward)."""
        self.data.qpos[:] = q
        self.data.qvel[:] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def load_torque(self, push):
        """J_tipᵀ of the external wrench on the tip, −F0 + push (base frame, at the tip site)."""
        out = np.zeros(self.model.nv)
        w = -self.f0 + push
        mujoco.mj_applyFT(self.model, self.data, w[:3].copy(), w[3:].copy(),
                          self.data.site_xpos[self.tip].copy(), self.tip_body, out)
        return out

    def residual(self, q, push=np.zeros(6)):
        """qfrc_passive + qfrc_actuator − qfrc_bias + J_xᵀ(−F0 + push) at rest at `q`."""
        self.at(q)
        d = self.data
        return d.qfrc_passive + d.qfrc_actuator - d.qfrc_bias + self.load_torque(push)

    def gravity_torque(self):
        self.at(self.q0)
        return self.data.qfrc_bias.copy()

    def tendon(self, q):
        """(ten_length, ten_J dense) at `q`."""
        self.at(q)
        m, d = self.model, self.data
        if d.ten_J.shape == (m.ntendon, m.nv):
            j = d.ten_J.copy()
        else:
            j = np.zeros((m.ntendon, m.nv))
            mujoco.mju_sparse2dense(j, d.ten_J, m.ten_J_rownnz, m.ten_J_rowadr, m.ten_J_colind)
        return d.ten_length.copy(), j

    def tip_pose(self, q):
        self.at(q)
        return self.data.site_xpos[self.tip].copy(), self.data.site_xmat[self.tip].reshape(3, 3).copy()

    def equilibrium(self, push, q=None, h=1e-6, tol=1e-11, iterations=30):
        """Newton on MuJoCo's residual, its matrix by central differences of the residual."""
        q = self.q0.copy() if q is None else q.copy()
        n = self.model.nv
        for _ in range(iterations):
            r = self.residual(q, push)
            jac = np.empty((n, n))
            for i in range(n):
                e = np.zeros(n)
                e[i] = h
                jac[:, i] = (self.residual(q + e, push) - self.residual(q - e, push)) / (2 * h)
            step = np.linalg.solve(jac, -r)
            q += step
            if np.max(np.abs(step)) < tol:
                break
        return q

    def deflection(self, q):
        """Tip displacement and rotation vector (base frame) from the exported pose."""
        p0, r0 = self.tip_pose(self.q0)
        p, r = self.tip_pose(q)
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, (r @ r0.T).ravel())
        rotvec = np.zeros(3)
        mujoco.mju_quat2Vel(rotvec, quat, 1.0)
        return np.concatenate([p - p0, rotvec])

    def stiffness(self, h=1e-6):
        """MuJoCo's tangent joint stiffness −∂R/∂q at the exported pose (central differences)."""
        n = self.model.nv
        k = np.empty((n, n))
        for i in range(n):
            e = np.zeros(n)
            e[i] = h
            k[:, i] = -(self.residual(self.q0 + e) - self.residual(self.q0 - e)) / (2 * h)
        return k

    def compliance(self, motion=1e-4):
        """C measured column by column: the symmetric probe (δx(+δw) − δx(−δw)) / 2δw at δw
        and 2δw, extrapolated (Richardson) to cancel the second-order term. Each δw is sized
        so the joints move about `motion` rad (from MuJoCo's own tangent stiffness): large
        enough to stay far above the residual's round-off, small enough that the fourth-order
        term is negligible on a soft arm (where K_q + K_W nearly cancels)."""
        k = self.stiffness()
        self.at(self.q0)
        jac = np.zeros((6, self.model.nv))
        mujoco.mj_jacSite(self.model, self.data, jac[:3], jac[3:], self.tip)
        c = np.zeros((6, 6))
        for col in range(6):
            e = np.zeros(6)
            e[col] = 1.0
            dq = np.linalg.norm(np.linalg.solve(k, jac.T @ e))
            if dq == 0.0:
                continue
            size = motion / dq
            probe = []
            for scale in (1.0, 2.0):
                push = scale * size * e
                plus = self.deflection(self.equilibrium(push))
                minus = self.deflection(self.equilibrium(-push))
                probe.append((plus - minus) / (2 * scale * size))
            c[:, col] = (4 * probe[0] - probe[1]) / 3
        return c

    def simulate(self, push, seconds, perturb=None):
        """Step from the exported pose at rest, the tip load applied every step; joint limits
        off (Sinew's model has none). Returns the final qpos and the largest |q − q0| seen."""
        m, d = self.model, self.data
        m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_LIMIT
        mujoco.mj_resetDataKeyframe(m, d, 0)
        if perturb is not None:
            d.qpos[:] += perturb
        mujoco.mj_forward(m, d)
        drift = 0.0
        for _ in range(int(round(seconds / m.opt.timestep))):
            d.qfrc_applied[:] = self.load_torque(push)
            mujoco.mj_step(m, d)
            drift = max(drift, float(np.max(np.abs(d.qpos - self.q0))))
        return d.qpos.copy(), drift
