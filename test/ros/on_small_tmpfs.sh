#!/bin/bash
# launch-prefix of disk_test.test: runs "$@" (a lab node) after mounting a tmpfs of $2 MB on
# its bag folder $1, a small disk that fills. Where no tmpfs may be mounted (not root), the
# node runs on the ordinary disk, and the tests that need a small one skip.
dir=$1
megabytes=$2
shift 2
mkdir -p "$dir"
mountpoint -q "$dir" || mount -t tmpfs -o "size=${megabytes}m" tmpfs "$dir" 2>/dev/null
exec "$@"
