//! Gmsh MSH 4.1 import (placeholder: being written).
