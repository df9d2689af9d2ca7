"""holofold.geometry: crease patterns, pattern generators, meshes and fabrication files.

The first layer: it imports nothing from the others. Lengths in metres, angles in radians
(fold angles in degrees, as FOLD has them); files a user opens use their format's convention
(meshes in millimetres unless asked otherwise, SVG in millimetres, FOLD in metres).
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "errors": [
            "ParameterError",
            "InvalidPatternError",
            "DegenerateGeometryError",
            "FormatError",
            "EnvironmentFault",
            "check_range",
        ],
        "arrangement": ["Arrangement", "arrange_lines"],
        "cuts": ["separate_cuts"],
        "export": ["export", "EXPORT_TYPES", "Format", "FORMATS", "register_format"],
        "fabrication": [
            "FabricationFile",
            "FabricationSet",
            "FileNames",
            "PATTERN_NAMES",
            "STRIP_NAMES",
            "write_fabrication_set",
            "export_pattern_files",
        ],
        "cutter": ["CutterProfile", "CutterOptions", "PROFILES", "DEFAULT_PROFILE", "get_profile"],
        "dxf": ["DXF_LAYERS", "export_dxf"],
        "thick": [
            "TECHNIQUES",
            "ThickPanels",
            "thick_panels",
            "path_overlap",
            "PathOverlap",
            "miura_path",
            "thick_panel_mesh",
            "thick_printable",
        ],
        "facets": ["split_faces", "nonconvex_faces", "SPLIT_MODES"],
        "families": [
            "Parameter",
            "PatternFamily",
            "pattern_families",
            "family_names",
            "get_family",
            "register_family",
        ],
        "fold_io": ["export_fold", "fold_dict", "load_fold", "read_fold", "FoldWarning"],
        "fold_frames": ["fold_path_dict", "export_fold_path"],
        "gripper": [
            "GripperPattern",
            "gripper_pattern",
            "miura_based_gripper",
            "splitted_miura_gripper",
            "two_panel_gripper",
            "DEFAULT_RANGE",
            "GRIPPER_NAMES",
        ],
        "bed": ["Bed", "DEFAULT_BED", "BedFit", "bed_fit", "place_on_bed", "print_time_text"],
        "segments": ["Segment", "Segmentation", "segment_part", "assembly_sheet", "write_segments"],
        "clearance": ["Printability", "printability", "panel_overlap", "panel_clearance"],
        "mesh": ["folded_mesh", "flat_mesh", "fan_triangulation", "MESH_UNITS"],
        "miura": [
            "miura_cell",
            "miura_sheet",
            "miura_sheet_paper",
            "miura_nodes",
            "miura_nodes_batch",
            "miura_faces",
        ],
        "inputs": ["check_input_file", "path_kind"],
        "outputs": [
            "check_output_path",
            "check_output_folder",
            "check_writable_folder",
            "atomic_write",
            "write_text",
            "write_json",
        ],
        "pattern": ["CreasePattern", "ASSIGNMENTS", "MAX_PANELS", "non_simple_faces"],
        "readers": [
            "read_pattern",
            "register_reader",
            "reader_for",
            "READERS",
            "PatternReader",
            "PatternWarning",
            "pattern_from_lines",
        ],
        "printable": [
            "PrintableLayout",
            "printable_layout",
            "printable_solid",
            "folded_printable_solid",
        ],
        "solid": ["thick_solid", "panel_solids", "shrunk_panels", "SolidWarning"],
        "svg": ["export_svg", "load_svg", "polylines_svg"],
        "tmp": ["tmp_sheet", "tmp_nodes", "tmp_faces"],
        "units": ["LENGTH_UNITS", "length_factor"],
        "vertex_sets": ["VertexSet", "parse_vertex_set", "VERTEX_SET_KINDS"],
    },
)
