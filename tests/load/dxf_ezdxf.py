"""Times ezdxf (a DXF library kerf did not write) reading the benchmark's drawing, for the
comparison with kerf's reader (solver/benches/dxf.rs): the file read and its model space's
entities walked with their coordinates, the least ezdxf does before a profile could be built.

Run by tests/load/dxf.sh after the bench; needs `pip install ezdxf==1.4.5`.
Usage: python3 tests/load/dxf_ezdxf.py FILE [RUNS]
"""
import sys
import time

import ezdxf


def main():
    path = sys.argv[1]
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    best = float("inf")
    for _ in range(runs):
        started = time.perf_counter()
        doc = ezdxf.readfile(path)
        count = 0
        total = 0.0
        for entity in doc.modelspace():
            if entity.dxftype() == "LINE":
                total += entity.dxf.start.x + entity.dxf.end.x
            elif entity.dxftype() == "CIRCLE":
                total += entity.dxf.radius
            count += 1
        best = min(best, time.perf_counter() - started)
    print(f"ezdxf {ezdxf.__version__}: {count} entities read in {best:.3f} s (best of {runs}): {count / best:,.0f} entities/s")


if __name__ == "__main__":
    main()
