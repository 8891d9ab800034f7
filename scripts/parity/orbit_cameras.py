"""24 orbit views, in cameras.json form, for shared scenes that come without cameras.

The raw trainer outputs (sh3_iter7000, train3, pc_short) have no cameras.json. Parity
needs views that look at their splats from all sides, near and far, so that view-dependent
colour (SH degree 3), large on-screen splats and far ones are all exercised. The views
circle the median of the splat centres at three distances (half, one and two times the
median distance of the centres from it, so a scene of outliers still fills the frame) and
two elevations (+-20 degrees), in the format of the trainer's cameras.json (800x800,
fx = fy = 857.8 as the shared cameras have; rotation = camera-to-world, OpenCV axes).
"""

import json
import math
from pathlib import Path

import numpy as np

VIEWS = 24
SIZE = 800
FOCAL = 857.8
DISTANCE_FACTORS = (0.5, 1.0, 2.0)
ELEVATIONS_DEG = (20.0, -20.0)


def look_at_rotation(eye, target, up):
    """Camera-to-world rotation with x right, y down, z forward (columns in world space)."""
    z = target - eye
    z /= np.linalg.norm(z)
    x = np.cross(-up, z)
    if np.linalg.norm(x) < 1e-9:  # looking along up: any right vector will do
        x = np.cross(np.array([1.0, 0.0, 0.0]), z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=1)


def orbit_cameras(means):
    """The 24 views around float array means [N, 3], as cameras.json entries."""
    means = np.asarray(means, dtype=np.float64)
    center = np.median(means, axis=0)
    spread = float(np.median(np.linalg.norm(means - center, axis=1)))
    # Three splats can sit almost on one point; the splats' own size then sets the frame.
    radius = max(spread, 1e-2 * max(1.0, float(np.abs(center).max())), 0.5)
    up = np.array([0.0, -1.0, 0.0])  # the trainer's COLMAP scenes are -Y up
    entries = []
    for i in range(VIEWS):
        azimuth = 2.0 * math.pi * i / VIEWS
        elevation = math.radians(ELEVATIONS_DEG[i % len(ELEVATIONS_DEG)])
        distance = radius * DISTANCE_FACTORS[i % len(DISTANCE_FACTORS)] * 2.0
        offset = np.array([math.cos(azimuth) * math.cos(elevation), -math.sin(elevation),
                           math.sin(azimuth) * math.cos(elevation)])
        eye = center + distance * offset
        rotation = look_at_rotation(eye, center, up)
        entries.append({"id": i, "img_name": f"orbit_{i:02d}", "width": SIZE, "height": SIZE,
                        "position": eye.tolist(), "rotation": rotation.tolist(),
                        "fx": FOCAL, "fy": FOCAL})
    return entries


def write_orbit_cameras(means, path):
    """Writes the views to path (a cameras.json) and returns them."""
    entries = orbit_cameras(means)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as f:
        json.dump(entries, f, indent=1)
    return entries
