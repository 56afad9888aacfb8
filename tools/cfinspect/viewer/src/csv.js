// Readers of cfreplay's output CSV and of its input trajectory (README, "cfreplay"). They
// throw an Error naming the file, the line and the problem; the page shows it.

import { Vector3 } from 'three';

const REPLAY_HEADER = 't,cf,pcs,motion,Fx,Fy,Fz,Mx,My,Mz';
const TRAJECTORY_HEADER = 't,tx,ty,tz,qw,qx,qy,qz';

function lines(text) {
  return text.split(/\r?\n/).filter((l, i, all) => l !== '' || i < all.length - 1);
}

function number(text, name, line, column) {
  const x = Number(text);
  if (text.trim() === '' || !Number.isFinite(x)) throw new Error(`${name} line ${line}: ${column} '${text}' is not a number`);
  return x;
}

export function parseReplay(text, name, numCfs) {
  const ls = lines(text);
  if (!ls.length || !ls[0].startsWith(REPLAY_HEADER))
    throw new Error(`${name}: not a cfreplay CSV (the header must start with '${REPLAY_HEADER}')`);
  const cols = ls[0].split(',');
  const at = (c) => cols.indexOf(c);
  const rows = [];
  for (let i = 1; i < ls.length; ++i) {
    const f = ls[i].split(',');
    if (f.length !== cols.length) throw new Error(`${name} line ${i + 1}: ${f.length} fields, expected ${cols.length}`);
    const cf = number(f[1], name, i + 1, 'cf');
    if (!Number.isInteger(cf) || cf < -1 || cf >= numCfs)
      throw new Error(`${name} line ${i + 1}: CF ${f[1]} is not in the graph (${numCfs} CFs)`);
    const v = (a, b, c) => new Vector3(...[a, b, c].map((k) => number(f[k], name, i + 1, cols[k])));
    // Where A was rendered, when the CSV says (cfreplay's proxy_* columns): the proxy pose,
    // which stays out of B while the device goes in.
    let proxy = null;
    if (at('proxy_tx') >= 0 && at('proxy_qz') >= 0) {
      const k0 = at('proxy_tx');
      const q = [0, 1, 2, 3, 4, 5, 6].map((k) => number(f[k0 + k], name, i + 1, cols[k0 + k]));
      proxy = quatPose(q[0], q[1], q[2], q[3], q[4], q[5], q[6], name, i + 1);
    }
    rows.push({ t: number(f[0], name, i + 1, 't'), cf, pcs: f[2], motion: f[3], F: v(4, 5, 6), M: v(7, 8, 9),
      status: at('status') >= 0 ? f[at('status')] : '', proxy });
  }
  if (!rows.length) throw new Error(`${name}: no rows after the header`);
  return rows;
}

// A pose {R: rows of the rotation, t} from a translation and a quaternion (normalised).
function quatPose(tx, ty, tz, qw0, qx0, qy0, qz0, name, line) {
  const n = Math.hypot(qw0, qx0, qy0, qz0);
  if (!(n > 0)) throw new Error(`${name} line ${line}: the quaternion is zero`);
  const [w, x, y, z] = [qw0 / n, qx0 / n, qy0 / n, qz0 / n];
  return {
    R: [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
      [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
      [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]],
    t: [tx, ty, tz],
  };
}

// Poses {R: rows of the rotation, t} from rows t,tx,ty,tz,qw,qx,qy,qz.
export function parseTrajectory(text, name) {
  const ls = lines(text);
  if (!ls.length || ls[0].trim() !== TRAJECTORY_HEADER) throw new Error(`${name}: the header must be '${TRAJECTORY_HEADER}'`);
  const poses = [];
  for (let i = 1; i < ls.length; ++i) {
    const f = ls[i].split(',');
    if (f.length !== 8) throw new Error(`${name} line ${i + 1}: ${f.length} fields, expected 8`);
    const [, tx, ty, tz, qw0, qx0, qy0, qz0] = f.map((x, k) => number(x, name, i + 1, TRAJECTORY_HEADER.split(',')[k]));
    poses.push(quatPose(tx, ty, tz, qw0, qx0, qy0, qz0, name, i + 1));
  }
  return poses;
}
