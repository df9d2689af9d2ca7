"""holofold.geometry: crease patterns, pattern generators, meshes and fabrication files.

The first layer: it imports nothing from the others. Lengths in metres, angles in radians
(fold angles in degrees, as FOLD has them); files a user opens use their format's convention.
"""

from holofold.geometry.errors import (
    DegenerateGeometryError,
    FormatError,
    InvalidPatternError,
    ParameterError,
    check_range,
)
from holofold.geometry.export import EXPORT_TYPES, export, export_pattern_files
from holofold.geometry.fold_io import FoldWarning, export_fold, fold_dict, load_fold
from holofold.geometry.gripper import (
    DEFAULT_RANGE,
    GRIPPER_NAMES,
    GripperPattern,
    gripper_pattern,
    miura_based_gripper,
    splitted_miura_gripper,
    two_panel_gripper,
)
from holofold.geometry.mesh import fan_triangulation, flat_mesh, folded_mesh
from holofold.geometry.miura import (
    miura_cell,
    miura_faces,
    miura_nodes,
    miura_sheet,
    miura_sheet_paper,
)
from holofold.geometry.outputs import atomic_write, check_output_path, write_json, write_text
from holofold.geometry.pattern import ASSIGNMENTS, CreasePattern
from holofold.geometry.solid import SolidWarning, panel_solids, shrunk_panels, thick_solid
from holofold.geometry.svg import export_svg, load_svg, polylines_svg
from holofold.geometry.tmp import tmp_faces, tmp_nodes, tmp_sheet

__all__ = [
    # the crease pattern
    "CreasePattern",
    "ASSIGNMENTS",
    # generators
    "miura_cell",
    "miura_sheet",
    "miura_sheet_paper",
    "miura_nodes",
    "miura_faces",
    "tmp_sheet",
    "tmp_nodes",
    "tmp_faces",
    "GripperPattern",
    "gripper_pattern",
    "miura_based_gripper",
    "splitted_miura_gripper",
    "two_panel_gripper",
    "DEFAULT_RANGE",
    "GRIPPER_NAMES",
    # meshes and solids
    "folded_mesh",
    "flat_mesh",
    "fan_triangulation",
    "thick_solid",
    "panel_solids",
    "shrunk_panels",
    "SolidWarning",
    # files
    "export",
    "export_pattern_files",
    "EXPORT_TYPES",
    "export_fold",
    "fold_dict",
    "load_fold",
    "FoldWarning",
    "export_svg",
    "load_svg",
    "polylines_svg",
    "check_output_path",
    "atomic_write",
    "write_text",
    "write_json",
    # errors
    "ParameterError",
    "InvalidPatternError",
    "DegenerateGeometryError",
    "FormatError",
    "check_range",
]
