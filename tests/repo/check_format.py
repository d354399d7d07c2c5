"""The C++ sources are formatted as .clang-format says: `clang-format --dry-run --Werror` on
every tracked .cpp/.h file (clang-format 14, Debian 12's; `make format` fixes them)."""
import os
import subprocess
import sys

root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
tool = os.environ.get("CLANG_FORMAT", "clang-format")
files = subprocess.run(["git", "-C", root, "ls-files", "*.cpp", "*.h"], check=True, capture_output=True,
                       text=True).stdout.split()
if not files:
    sys.exit(f"{root}: no C++ files found")
bad = []
for start in range(0, len(files), 50):
    chunk = files[start:start + 50]
    result = subprocess.run([tool, "--dry-run", "--Werror", *chunk], cwd=root, capture_output=True, text=True)
    if result.returncode != 0:
        bad += sorted({line.split(":", 1)[0] for line in result.stderr.splitlines() if ": error:" in line})
for path in bad:
    print(f"{path}: not formatted as .clang-format says (run `make format`)")
print(f"{len(files)} files checked, {len(bad)} not formatted")
sys.exit(1 if bad else 0)
