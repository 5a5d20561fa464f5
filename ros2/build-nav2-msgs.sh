#!/usr/bin/env bash
# Build ros2/nav2_msgs (NavigateToPose) into a ROS 2 venv made from requirements-ros2.txt:
#   ros2/build-nav2-msgs.sh .venv-ros2 BUILD_DIR
# The message libraries go to VENV/lib (which the wheels' start-up hook puts on
# LD_LIBRARY_PATH) and the Python package to VENV's site-packages, as the wheels' own are.
set -euo pipefail
venv=$(cd "$1" && pwd)
build=$2
source_dir=$(cd "$(dirname "$0")/nav2_msgs" && pwd)
python=$venv/bin/python

# The wheels were built in a manylinux image: their exported CMake files name that image's
# Python and numpy include directories. Point them at this venv's before CMake reads them.
py_include=$("$python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
np_include=$("$python" -c 'import numpy; print(numpy.get_include())')
{ grep -rlZ --include='*.cmake' '/opt/python/cp311-cp311/' "$venv/share" || true; } | xargs -0 -r sed -i \
	-e "s#/opt/python/cp311-cp311/include/python3.11#$py_include#g" \
	-e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include#$np_include#g"

export PATH="$venv/bin:$PATH"
mkdir -p "$build"
# Quiet unless something fails: then the whole log.
log=$build/build.log
{
cmake -S "$source_dir" -B "$build" -G Ninja -Wno-author --log-level=WARNING \
	-DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF \
	-DCMAKE_PREFIX_PATH="$venv" -DCMAKE_INSTALL_PREFIX="$venv" \
	-DPython3_EXECUTABLE="$python"
cmake --build "$build"
cmake --install "$build"
} >"$log" 2>&1 || { cat "$log"; exit 1; }
# The check that it is usable: the action's Jazzy fields, imported as a node would.
"$python" -c 'from nav2_msgs.action import NavigateToPose as A; assert "error_msg" in A.Result.get_fields_and_field_types()'
