#!/bin/bash
# Lists what a shared library of mrgi's exports and fails on anything that is not the public API:
# an internal mrgi:: function, a third-party symbol (stb_image, tinygltf, nlohmann::json, Eigen,
# meshoptimizer, ...), or anything else outside the headers. Allowed:
#   - mrgi:: functions and members declared in the public headers (HEADER_DIR/mrgi/**.h), and
#     the type information and vtables of the classes declared there;
#   - weak (vague-linkage) instantiations of std:: templates, which every library that uses them
#     carries and the dynamic linker merges;
#   - the ELF markers every shared object defines (_init, _fini, _edata, _end, __bss_start).
# It also checks that the entry points an app starts from are exported, so a library that
# exports nothing fails too. Names are compared without their parameters: an overload of a public
# name passes. (What a library needs from libmrgi.so that it does not export fails their link:
# -Wl,--no-undefined, cmake/MrgiSharedLibrary.cmake.)
# Usage: exported_symbols_test.sh LIBRARY HEADERS [HEADERS...] [-- REQUIRED_SYMBOL...]
#   HEADERS: header files, or folders searched for *.h
set -euo pipefail
lib=$1
shift
headers=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do headers+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
required=("$@")
work=$(mktemp -d "${TMPDIR:-/tmp}/mrgi-exports.XXXXXX")
trap 'rm -rf "$work"' EXIT

# The public API's names, from the headers: NAME at namespace scope becomes mrgi::NAME, a member
# of class or struct C mrgi::C::NAME, and mrgi::C itself (type information, vtable).
find "${headers[@]}" -name '*.h' -print0 | xargs -0 cat | awk '
  { sub(/\/\/.*/, "") }                        # comments
  /^#/ { next }
  {
    line = $0
    if (match(line, /^(class|struct)( MRGI_API)? [A-Za-z_][A-Za-z0-9_]*/)) {
      n = split(substr(line, RSTART, RLENGTH), w, " ")
      cls = w[n]
      if (index(line, "{") && depth == 1) { pending = cls }
      print "mrgi::" cls
    }
    # a static data member: static [constexpr] TYPE NAME = ... / ;
    if (depth == 2 && current != "" && match(line, /static[^(=;]*[ *&][A-Za-z_][A-Za-z0-9_]* *(=|;|\{)/)) {
      decl = substr(line, RSTART, RLENGTH); sub(/ *(=|;|\{)$/, "", decl)
      n = split(decl, w, /[ *&]+/)
      print "mrgi::" current "::" w[n]
    }
    rest = line
    while (match(rest, /(~?[A-Za-z_][A-Za-z0-9_]*|operator[^ (A-Za-z0-9_]+) *\(/)) {
      name = substr(rest, RSTART, RLENGTH); sub(/ *\($/, "", name)
      if (depth == 1) print "mrgi::" name
      else if (depth == 2 && current != "") print "mrgi::" current "::" name
      rest = substr(rest, RSTART + RLENGTH)
    }
    opens = gsub(/\{/, "{", line); closes = gsub(/\}/, "}", line)
    if (pending != "" && opens > 0) { current = pending; pending = "" }
    depth += opens - closes
    if (depth <= 1) current = ""
  }' | sort -u > "$work/api"
test -s "$work/api" || { echo "no declarations found under ${headers[*]}"; exit 1; }

nm -D --defined-only "$lib" | c++filt > "$work/exports"
bad=0
while IFS= read -r line; do
  type=$(echo "$line" | cut -d' ' -f2)
  sym=$(echo "$line" | cut -d' ' -f3-)
  case "$sym" in
    _init|_fini|_edata|_end|__bss_start) continue ;;
  esac
  name=$sym
  kind=function
  for prefix in "typeinfo name for " "typeinfo for " "vtable for " "VTT for "; do
    if [ "${name#"$prefix"}" != "$name" ]; then name=${name#"$prefix"}; kind=type; fi
  done
  # A template function's demangled name starts with its return type; an ABI tag is not a name.
  name=$(echo "$name" | sed -E 's/^(void|bool|char|int|long|unsigned|unsigned int|unsigned long|float|double) //; s/\[abi:[a-z0-9]+\]//g')
  if [[ "$name" == std::* || "$name" == __gnu_cxx::* ]]; then
    case "$type" in W|V|u) continue ;; esac
    echo "not weak: $type $sym"; bad=$((bad + 1)); continue
  fi
  qualified=${name%%(*}
  if [ "$kind" = function ] && [[ "$qualified" != mrgi::* ]]; then
    echo "not mrgi's: $type $sym"; bad=$((bad + 1)); continue
  fi
  if ! grep -qxF -- "$qualified" "$work/api"; then
    echo "not in the public headers: $type $sym"; bad=$((bad + 1))
  fi
done < "$work/exports"
for r in "${required[@]}"; do
  # (grep without -q: it reads to the end, so cut never dies of SIGPIPE, which pipefail would
  # take for a missing symbol)
  if ! cut -d' ' -f3- "$work/exports" | grep -- "^$r(" > /dev/null; then
    echo "the public entry point $r is not exported"; bad=$((bad + 1))
  fi
done
total=$(wc -l < "$work/exports")
if [ "$bad" -gt 0 ]; then
  echo "$(basename "$lib"): $bad findings above, among $total exported symbols"; exit 1
fi
echo "$(basename "$lib"): $total exported symbols, all the public API"
