"""What the Python tests share: the source tree, the mechopt binary (ctest
sets MECHOPT_SOURCE_DIR and MECHOPT_BINARY) and the configs they use."""
import os

SOURCE = os.environ.get("MECHOPT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
BINARY = os.environ.get("MECHOPT_BINARY", os.path.join(SOURCE, "build", "bin", "mechopt"))
TWIN = os.path.join(SOURCE, "configs", "recuperative_drive", "rod_length.yaml")
CONVEYOR = os.path.join(SOURCE, "configs", "linkage", "conveyor_swing.yaml")
