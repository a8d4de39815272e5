#!/bin/sh
# NLopt's source for the playground's design (web/CMakeLists.txt): Debian's source package, the one
# Debian builds the native build's libnlopt from (the installed version when there is one), fetched with
# apt-get into private lists and caches -- the machine's own apt state is not touched and no root is
# needed -- and unpacked with Debian's patches into DEST. The deb-src lines are the machine's deb lines.
# Exit status non-zero when it cannot (no network, no such package): the caller goes on without it.
#   fetch_nlopt.sh DEST SCRATCH
set -eu
dest=$1
work=$2
rm -rf "$work"
mkdir -p "$work/parts" "$work/lists/partial" "$work/cache/archives/partial" "$work/src"
# deb-src entries from the machine's deb entries (one-line .list files and deb822 .sources files)
for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
  [ -f "$f" ] && sed -n 's/^[[:space:]]*deb[[:space:]]/deb-src /p' "$f" >>"$work/parts/plate.list"
done
for f in /etc/apt/sources.list.d/*.sources; do
  [ -f "$f" ] && sed 's/^Types:.*/Types: deb-src/' "$f" >"$work/parts/$(basename "$f")"
done
touch "$work/parts/plate.list"
apt() {
  apt-get -q -o Dir::Etc::SourceList=/dev/null -o Dir::Etc::SourceParts="$work/parts" \
    -o Dir::State::Lists="$work/lists" -o Dir::Cache="$work/cache" -o APT::Sandbox::User="$(id -un)" "$@"
}
apt update >"$work/update.log" 2>&1 || { cat "$work/update.log" >&2; exit 1; }
version=$(dpkg-query -W -f='${source:Version}' libnlopt0 2>/dev/null || true)
cd "$work/src"
apt source --download-only "nlopt${version:+=$version}" >&2
dpkg-source -x ./nlopt_*.dsc nlopt >&2
rm -rf "$dest"
mv nlopt "$dest"
echo "NLopt ${version:-(newest)} from Debian's source package in $dest"
