"""Motion data: rotations, DeepMimic clips, forward kinematics, pose features, B-splines.

Conventions (docs/motion.md): quaternions ``x, y, z, w``; the world as in the data (y-up for
the DeepMimic humanoid, which faces +x with its right side towards +z). Submodules import numpy
(and h5py inside functions); forward kinematics comes from a simulator plugin
(``kinematics.engine``); ``rotations_torch`` is the only one importing torch and is not imported
here.
"""

from toolkit.motion.clips import Clip, ClipError, load_clip, load_humanoid_clips
from toolkit.motion.dataset import PoseDataset, build_dataset, load_dataset
from toolkit.motion.features import (
    CONDITION_NAMES,
    FeatureLayout,
    clip_features,
    feature_layout,
    features_to_joints,
    getup_conditions,
    pose_features,
)
from toolkit.motion.kinematics import Kinematics, Velocities, clip_velocities, forward_kinematics
from toolkit.motion.skeletons import HUMANOID, LAIKAGO, Skeleton, humanoid_clip_paths, motions_dir
from toolkit.motion.splines import BSplineCurve, normalised_time

__all__ = [
    "BSplineCurve",
    "CONDITION_NAMES",
    "Clip",
    "ClipError",
    "FeatureLayout",
    "HUMANOID",
    "Kinematics",
    "LAIKAGO",
    "PoseDataset",
    "Skeleton",
    "Velocities",
    "build_dataset",
    "clip_features",
    "clip_velocities",
    "feature_layout",
    "features_to_joints",
    "forward_kinematics",
    "getup_conditions",
    "humanoid_clip_paths",
    "load_clip",
    "load_dataset",
    "load_humanoid_clips",
    "motions_dir",
    "normalised_time",
    "pose_features",
]
