#!/usr/bin/env bash
# A command that holds CT-sized volumes runs with transparent huge pages
# (glibc.malloc.hugetlb=1) where the kernel gives them only on request, and
# says so in its provenance; a user's own tunables are kept, their choice on
# huge pages too; a command without volumes (fit) does not restart. A build
# with AddressSanitizer, whose allocator ignores the tunable, never restarts.
source "$(dirname "$0")/common.bash"

mode=$(cat /sys/kernel/mm/transparent_hugepage/enabled 2> /dev/null || echo none)
asked=no
[[ $mode == *"[madvise]"* ]] && asked=yes
# (read whole, not piped to grep -q: under pipefail its early exit fails ldd)
[[ $(ldd "$bin/articula") == *libasan* ]] && asked=no

# phantom_tunables FOLDER [VARIABLE=VALUE]: the glibc_tunables a phantom's
# provenance records ("-": none), run without the caller's GLIBC_TUNABLES,
# with the given one if any.
phantom_tunables() {
  local folder=$1; shift
  env -u GLIBC_TUNABLES "$@" "$bin/articula" phantom -o "$folder" --spacing 2.5,2.5,3 --no-dicom --quiet
  python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["provenance"].get("glibc_tunables", "-"))' "$folder/truth.json"
}
got=$(phantom_tunables "$tmp/a")
mine=$(phantom_tunables "$tmp/b" GLIBC_TUNABLES=glibc.malloc.arena_max=2)
declined=$(phantom_tunables "$tmp/c" GLIBC_TUNABLES=glibc.malloc.hugetlb=0)
echo "kernel: $mode; asked: $asked; recorded: '$got', '$mine', '$declined'"
if [ "$asked" = yes ]; then
  [ "$got" = "glibc.malloc.hugetlb=1" ] || fail "no huge pages asked for: $got"
  [ "$mine" = "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1" ] || fail "the user's tunables: $mine"
else
  [ "$got" = "-" ] || fail "huge pages asked for where they do not help: $got"
  [ "$mine" = "glibc.malloc.arena_max=2" ] || fail "the user's tunables: $mine"
fi
[ "$declined" = "glibc.malloc.hugetlb=0" ] || fail "the user's choice on huge pages: $declined"

# fit holds no volume: no restart, no tunable.
"$bin/articula" surface --model sphere -o "$tmp/sphere.ply" --quiet
env -u GLIBC_TUNABLES "$bin/articula" fit -i "$tmp/sphere.ply" -o "$tmp/fits.json" --models sphere --quiet
python3 -c 'import json, sys; p = json.load(open(sys.argv[1]))["provenance"]; assert "glibc_tunables" not in p, p' "$tmp/fits.json"
echo "huge pages: ok"
