#!/usr/bin/env bash
# Hostile input through the tools, end to end (issue 17; docs/bad-input.md lists every case
# by its name here). Each case runs a tool under a 20 s timeout and checks the exit status,
# that stderr matches a regular expression (the message, not just a failure), that nothing
# was echoed raw, and that no output or temporary file was left behind.
#
#   hostile_test.sh GROUP TOOL_DIR SOURCE_DIR WORK_DIR
#     GROUP     cfgen | cfinspect | cfreplay (one ctest each)
#     TOOL_DIR  the directory holding cfgen, cfreplay and cfinspect/cfinspect
set -uo pipefail
group="$1"
tools="$2"
src="$3"
work="$4/hostile_$group"
rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 1

CFGEN="$tools/cfgen"
CFREPLAY="$tools/cfreplay"
CFINSPECT="$tools/cfinspect/cfinspect"
M="$src/data/models"
G="$src/tests/data/graphs/box_l.json"
GEN="$src/data/graphs/cube_l_block.json"  # cfgen's graph of the cube and the L-block
T="$src/data/trajectories/cube_lblock_corner.csv"
# A trajectory that fits box_l.json (a few poses of the cube resting on the L-block's floor).
printf 't,tx,ty,tz,qw,qx,qy,qz\n0,20,10.3,5,1,0,0,0\n0.001,20,10.3,5,1,0,0,0\n' >poses.csv
P="$work/poses.csv"

pass=0
fail=0
report() {  # name ok message
  if [[ "$2" == 1 ]]; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    printf 'FAIL %s: %s\n' "$1" "$3"
  fi
}

# check NAME STATUS REGEX -- COMMAND...
#   STATUS: the exit status expected; REGEX: extended regex stderr must match.
check() {
  local name="$1" want="$2" regex="$3"
  shift 4
  local err rc
  err=$(timeout 20 "$@" 2>&1 >/dev/null)
  rc=$?
  if [[ $rc == 124 ]]; then report "$name" 0 "timed out (a hang)"; return; fi
  if [[ $rc -ge 128 ]]; then report "$name" 0 "killed by signal $((rc - 128)): $err"; return; fi
  if [[ "$rc" != "$want" ]]; then report "$name" 0 "exit status $rc, expected $want; stderr: $err"; return; fi
  if ! grep -Eq -- "$regex" <<<"$err"; then report "$name" 0 "stderr does not match '$regex': $err"; return; fi
  if LC_ALL=C grep -q '[^[:print:][:space:]]' <<<"$err"; then report "$name" 0 "raw bytes echoed: $err"; return; fi
  if [[ "$want" != 0 ]] && [[ $(grep -cv 'warning:' <<<"$err") -ne 1 ]]; then
    report "$name" 0 "expected one error line: $err"
    return
  fi
  report "$name" 1 ""
}

# absent NAME PATH...: none of the files exist (no output, no temporary file left).
absent() {
  local name="$1" p
  shift
  for p in "$@"; do
    if [[ -e "$p" || -L "$p" ]]; then report "$name" 0 "'$p' was left behind"; return; fi
  done
  if compgen -G "$work/*.tmp*" >/dev/null; then report "$name" 0 "temporary files left: $(ls "$work"/*.tmp*)"; return; fi
  report "$name" 1 ""
}

mkfifo fifo.json fifo.csv fifo.off fifo.cbor out_fifo.json out_fifo.csv
mkdir dir.json dir.csv dir.off

# ---------------------------------------------------------------------------------------
if [[ "$group" == cfgen ]]; then
  # Model files whose headers lie about their size, and bad numbers.
  printf 'OFF\n3 999999999 0\n0 0 0\n1 0 0\n0 1 0\n' >count.off
  check off_header_count 1 "count.off': parse error: the header says 3 vertices and 999999999 facets, more than the remaining [0-9]+ bytes" -- "$CFGEN" --features count.off
  printf 'OFF\n999999999 1 0\n0 0 0\n' >vcount.off
  check off_vertex_count 1 "vcount.off': parse error: the header says 999999999 vertices" -- "$CFGEN" --features vcount.off
  printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n' >facet.off
  check off_facet_size 1 "facet.off': parse error: line 6: facet 0 says it has 1000000000 vertices but its line lists 3 numbers" -- "$CFGEN" --features facet.off
  sed 's/^4 0 3 2 1$/4 99999999999999999999 3 2 1/' "$M/cube.off" >index.off
  check off_index_20_digits 1 "index.off': parse error: line [0-9]+: facet 0 refers to vertex 99999999999999999999 but the file has 8 vertices \(0 to 7\)" -- "$CFGEN" --features index.off
  printf 'OFF\n4 4 0\n0 0 0\n1e301 0 0\n0 1e301 0\n0 0 1e301\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' >huge.off
  check off_huge_coordinates 1 "huge.off': vertex 1 has the coordinate 1e\+301 mm, beyond the largest accepted \(\|x\| <= 1e\+09 mm\)" -- "$CFGEN" --features huge.off
  printf 'OFF\n4 4 0\n0 0 0\nnan 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' >nan.off
  check off_nan 1 "nan.off': parse error: line 4: vertex 1: 'nan' is not a finite number" -- "$CFGEN" --features nan.off
  printf 'OFF BINARY\n' >bin.off
  check off_binary 1 "bin.off': parse error: line 1: binary OFF is not supported" -- "$CFGEN" --features bin.off
  printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n' >index.obj
  check obj_index_20_digits 1 "index.obj': parse error: line 4: facet 0 refers to vertex 99999999999999999999, which does not exist" -- "$CFGEN" --features index.obj
  printf 'v 0 0 0\n\x01\x02\xff junk\n' >garbage.obj
  check obj_garbage 1 "garbage.obj': parse error: line 2: unknown OBJ record '\\\\x01\\\\x02\\\\xFF'" -- "$CFGEN" --features garbage.obj
  printf 'ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n' >count.ply
  check ply_header_count 1 "count.ply': parse error: the header's element counts need at least 48000000000 bytes of data, but the file has 0" -- "$CFGEN" --features count.ply
  printf 'ply\nformat ascii 1.0\nelement junk 4000000000\nend_header\n' >noprop.ply
  check ply_element_without_properties 1 "noprop.ply': parse error: element 'junk' has 4000000000 items but no properties" -- "$CFGEN" --features noprop.ply
  head -c 80 /dev/zero >count.stl
  printf '\xff\xff\xff\x7f' >>count.stl
  check stl_binary_count 1 "count.stl': parse error: not an ascii STL \(no 'solid'\), and as binary STL its header says 2147483647 triangles \([0-9]+ bytes\) but the file has 84 bytes" -- "$CFGEN" --features count.stl
  check model_fifo 1 "fifo.off': cannot open file: is a FIFO \(named pipe\), not a regular file" -- "$CFGEN" --features fifo.off
  check path_escapes 1 "^cfgen: loading '\\\\x1B\[2J\\\\x1B\[31mred\.off': cannot open file: no such file" -- "$CFGEN" --features $'\e[2J\e[31mred.off'
  check model_directory 1 "dir.off': cannot open file: is a directory, not a regular file" -- "$CFGEN" --features dir.off

  # Options: finite and in range, the range in --help.
  for opt in --touch-tol --min-clearance --good-clearance --min-margin --angle-margin --resolution --coplanar-tol --crease-angle; do
    check "cfgen${opt}_nan" 2 "^cfgen: ${opt}: 'nan' is not a finite number" -- "$CFGEN" "$M/cube.off" "$M/l_block.off" -o nan.json "$opt" nan
    check "cfgen${opt}_inf" 2 "^cfgen: ${opt}: 'inf' is not a finite number" -- "$CFGEN" "$M/cube.off" "$M/l_block.off" -o nan.json "$opt" inf
  done
  check cfgen_touch_tol_range 2 "^cfgen: --touch-tol: '1' is outside \[[-+.e0-9]+, [-+.e0-9]+\]" -- "$CFGEN" "$M/cube.off" "$M/l_block.off" -o nan.json --touch-tol 1
  check cfgen_resolution_range 2 "^cfgen: --resolution: '1' is outside \[1e-09, 0.1\]" -- "$CFGEN" "$M/cube.off" "$M/l_block.off" -o nan.json --resolution 1
  check cfgen_threads_range 2 "^cfgen: --threads: Value 100000 not in range 0 to 1024" -- "$CFGEN" "$M/cube.off" "$M/l_block.off" -o nan.json -j 100000
  check cfgen_good_below_min_clearance 2 "^cfgen: --good-clearance 0.0001 is below --min-clearance 0.0002: a witness is kept only when its clearance reaches --min-clearance" -- "$CFGEN" "$M/cube.off" "$M/l_block.off" -o nan.json --good-clearance 1e-4
  check cfgen_min_above_good_clearance 2 "^cfgen: --good-clearance 0.02 is below --min-clearance 0.03" -- "$CFGEN" "$M/cube.off" "$M/l_block.off" -o nan.json --min-clearance 0.03
  absent cfgen_bad_options_no_output nan.json
  help=$("$CFGEN" --help)
  if grep -q -- '--coplanar-tol FLOAT:\[1e-12, 0.1\]' <<<"$help" && grep -q -- '--touch-tol FLOAT:\[[-+.e0-9]*, [-+.e0-9]*\]' <<<"$help"; then
    report cfgen_help_ranges 1 ""
  else
    report cfgen_help_ranges 0 "--help does not list the ranges"
  fi
  # The largest tolerance --help allows is one the loader takes.
  check cfgen_coplanar_tol_max 0 "^$" -- "$CFGEN" --features "$M/cube.off" --coplanar-tol 0.1
  check cfgen_crease_angle_range 2 "^cfgen: --crease-angle: '181' is outside \[0, 180\]" -- "$CFGEN" --features "$M/cube.off" --crease-angle 181
  check cfgen_crease_angle_ends 0 "^$" -- "$CFGEN" --features "$M/cube.off" --crease-angle 0 --coplanar-tol 0.1
  check cfgen_units_unknown 2 "^cfgen: --units: .*furlong" -- "$CFGEN" --features "$M/cube.off" --units furlong

  # Units: a 30 mm cube written in metres.
  awk 'NR>3 && NF==3 {printf "%g %g %g\n", $1/1000, $2/1000, $3/1000; next} {print}' "$M/cube.off" >cube_m.off
  check units_small_warning 0 "cfgen: warning: model 'cube_m' is 0.05196 mm across \(bounding-box diagonal\), small against the contact threshold epsilon = 1 mm .*--units" -- "$CFGEN" --features cube_m.off
  check units_m_no_warning 0 "^$" -- "$CFGEN" --features cube_m.off --units m
  features=$("$CFGEN" --features cube_m.off --units m 2>/dev/null | tr -d ' \n')
  if grep -q '"vertices":\[\[-15.0,-15.0,-15.0\]' <<<"$features"; then report units_m_scaled 1 ""; else report units_m_scaled 0 "not scaled to mm: ${features:0:200}"; fi
  awk 'NR>3 && NF==3 {printf "%g %g %g\n", $1*1000, $2*1000, $3*1000; next} {print}' "$M/l_block.off" >l_block_um.off
  check units_large_warning 0 "cfgen: warning: model 'l_block_um' is 1.649e\+05 mm across .*large against the contact threshold" -- "$CFGEN" --features l_block_um.off

  # Output paths: devices, FIFOs, directories, the inputs; symlinks followed.
  cp "$M/cube.off" a.off
  check out_device 1 "writing graph '/dev/null': is a character device; output files must be regular files" -- "$CFGEN" a.off "$M/l_block.off" -o /dev/null
  check out_fifo 1 "writing graph 'out_fifo.json': is a FIFO \(named pipe\); output files must be regular files" -- "$CFGEN" a.off "$M/l_block.off" -o out_fifo.json
  check out_directory 1 "writing graph 'dir.json': is a directory; output files must be regular files" -- "$CFGEN" a.off "$M/l_block.off" -o dir.json
  check out_trailing_slash 1 "writing graph 'new/': names a directory, not a file" -- "$CFGEN" a.off "$M/l_block.off" -o new/
  check out_is_input 1 "writing graph 'a.off': is an input of this run; refusing to overwrite it" -- "$CFGEN" a.off "$M/l_block.off" -o a.off
  ln -s a.off link_to_a.off
  check out_links_to_input 1 "writing graph 'link_to_a.off': is the same file as the input 'a.off'" -- "$CFGEN" a.off "$M/l_block.off" -o link_to_a.off
  mkdir -p ck_dir
  check out_in_checkpoint 1 "^cfgen: writing graph 'ck_dir/checkpoint.json': is inside the checkpoint directory 'ck_dir'" -- "$CFGEN" a.off "$M/l_block.off" --checkpoint ck_dir -o ck_dir/checkpoint.json
  long_name=$(printf 'g%.0s' {1..250}).json
  check out_longest_name 0 "" -- "$CFGEN" a.off "$M/l_block.off" -q --max-pcs 1 -o "$long_name"
  rm -f "$long_name"
  check out_no_directory 1 "writing graph 'no/such/g.json': the directory 'no/such' does not exist" -- "$CFGEN" a.off "$M/l_block.off" -o no/such/g.json
  if cmp -s a.off "$M/cube.off" && [[ -p out_fifo.json && -d dir.json ]]; then report out_inputs_intact 1 ""; else report out_inputs_intact 0 "an input or special file was changed"; fi
  absent out_nothing_left new no
fi

# ---------------------------------------------------------------------------------------
if [[ "$group" == cfinspect ]]; then
  check graph_fifo 1 "^cfinspect: reading 'fifo.json': cannot open: is a FIFO \(named pipe\), not a regular file" -- "$CFINSPECT" fifo.json
  check graph_fifo_cbor 1 "^cfinspect: reading 'fifo.cbor': cannot open: is a FIFO" -- "$CFINSPECT" fifo.cbor
  # A path holding terminal escapes is quoted with them made visible.
  check path_escapes 1 "^cfinspect: reading '\\\\x1B\[5mblink\\\\xC2\\\\x9B\.json': cannot open: no such file" -- "$CFINSPECT" $'\e[5mblink\xc2\x9b.json'
  check graph_directory 1 "^cfinspect: reading 'dir.json': cannot open: is a directory, not a regular file" -- "$CFINSPECT" dir.json
  check graph_device 1 "^cfinspect: reading '/dev/zero': cannot open: is a character device, not a regular file" -- "$CFINSPECT" /dev/zero
  python3 -c "import sys; sys.stdout.buffer.write(b'\xa1\x61x' + b'\x81' * 100000 + b'\xf6')" >deep.cbor
  check cbor_deep_nesting 1 "^cfinspect: reading 'deep.cbor': not valid CBOR: nesting deeper than 256 levels" -- "$CFINSPECT" deep.cbor
  python3 -c "import sys; sys.stdout.write('{\"format\":\"cf-graph\",\"version\":1,\"x\":' + '[' * 100000 + ']' * 100000 + '}')" >deep.json
  check json_deep_nesting 1 "^cfinspect: reading 'deep.json': not valid JSON: .*nesting deeper than 256 levels" -- "$CFINSPECT" deep.json
  # A member of millions of nulls in a file that names no format: refused as no graph before
  # the member is read (10 million took 470 MB and 6 s as JSON, 3.8 GB and 44 s as CBOR).
  python3 -c "import sys; sys.stdout.write('{\"x\":[' + 'null,' * 1999999 + 'null]}')" >nulls.json
  check nulls_without_format 1 "^cfinspect: reading 'nulls.json' at /: missing member \"format\": not a cf-graph file" -- "$CFINSPECT" nulls.json
  python3 -c "import sys; sys.stdout.buffer.write(b'\xa1\x61x\x9b' + (2 * 10**6).to_bytes(8, 'big') + b'\xf6' * (2 * 10**6))" >nulls.cbor
  check nulls_without_format_cbor 1 "^cfinspect: reading 'nulls.cbor' at /: missing member \"format\": not a cf-graph file" -- "$CFINSPECT" nulls.cbor
  # A graph's header, then a metadata member of 3 million nulls: refused after 2^21 values,
  # before a DOM of them is built.
  python3 -c "import sys; sys.stdout.write('{\"format\":\"cf-graph\",\"version\":1,\"x\":[' + ','.join(['null'] * 3000000) + ']}')" >big_meta.json
  check big_metadata 1 "^cfinspect: reading 'big_meta.json' at /x: the members other than cfs and transitions hold more than 2097152 values" -- "$CFINSPECT" big_meta.json
  python3 -c "import sys; sys.stdout.buffer.write(b'\xa3\x66format\x68cf-graph\x67version\x01\x61x\x9b' + (3 * 10**6).to_bytes(8, 'big') + b'\xf6' * (3 * 10**6))" >big_meta.cbor
  check big_metadata_cbor 1 "^cfinspect: reading 'big_meta.cbor' at /x: the members other than cfs and transitions hold more than 2097152 values" -- "$CFINSPECT" big_meta.cbor
  # A member named twice: refused, with the second one's place.
  printf '{"format":"cf-graph","version":1,"format":"x"}' >twice.json
  check member_twice 1 "^cfinspect: reading 'twice.json' at /format: member \"format\" appears twice in this object \(each name once\)" -- "$CFINSPECT" twice.json
  # A CBOR graph (box_l) with 100,000 nested arrays in a CF's extra member.
  python3 - "$G" <<'EOF' >deep_cf.cbor
import json, struct, sys
g = json.load(open(sys.argv[1]))
def enc(v):  # a small CBOR encoder: enough for a graph
    def head(major, n):
        if n < 24: return bytes([major << 5 | n])
        for ai, fmt in ((24, '>B'), (25, '>H'), (26, '>I'), (27, '>Q')):
            try: return bytes([major << 5 | ai]) + struct.pack(fmt, n)
            except struct.error: pass
    if v is None: return b'\xf6'
    if v is True: return b'\xf5'
    if v is False: return b'\xf4'
    if isinstance(v, int): return head(0, v) if v >= 0 else head(1, -1 - v)
    if isinstance(v, float): return b'\xfb' + struct.pack('>d', v)
    if isinstance(v, str): b = v.encode(); return head(3, len(b)) + b
    if isinstance(v, list): return head(4, len(v)) + b''.join(enc(x) for x in v)
    if isinstance(v, dict): return head(5, len(v)) + b''.join(enc(k) + enc(x) for k, x in v.items())
    if isinstance(v, bytes): return v
g['cfs'][0]['extra'] = b'\x81' * 100000 + b'\xf6'
sys.stdout.buffer.write(enc(g))
EOF
  check cbor_deep_nesting_in_cf 1 "^cfinspect: reading 'deep_cf.cbor': not valid CBOR: nesting deeper than 256 levels" -- "$CFINSPECT" deep_cf.cbor
  head -c 2000 /dev/urandom >garbage.json
  check graph_binary_garbage 1 "^cfinspect: reading 'garbage.json': not valid JSON" -- "$CFINSPECT" garbage.json
  # Quaternions: one tolerance for every tool (1e-3 on the norm).
  check pose_4_decimals 0 "^$" -- "$CFINSPECT" "$G" --pose 20,10.3,5,0.7071,0.7071,0,0
  check pose_not_unit 1 "^cfinspect: --pose '20,10.3,5,1,0.1,0,0': the quaternion \(qw,qx,qy,qz\) has norm 1.00498756, not 1 within 0.001" -- "$CFINSPECT" "$G" --pose 20,10.3,5,1,0.1,0,0
  check pose_nan 1 "^cfinspect: --pose '20,10.3,5,nan,0,0,0': the quaternion \(qw,qx,qy,qz\) has norm nan" -- "$CFINSPECT" "$G" --pose 20,10.3,5,nan,0,0,0
  check epsilon_nan 2 "^cfinspect: --epsilon-mm: 'nan' is not a finite number" -- "$CFINSPECT" "$G" --pose 20,10.3,5,1,0,0,0 --epsilon-mm nan
  check epsilon_huge 2 "^cfinspect: --epsilon-mm: '1e308' is outside \[1e-06, 1000\]" -- "$CFINSPECT" "$G" --pose 20,10.3,5,1,0,0,0 --epsilon-mm 1e308
  check epsilon_old_name_warns 0 "^cfinspect: warning: --epsilon is now --epsilon-mm; the old name goes in the next release" -- "$CFINSPECT" "$G" --pose 20,10.3,5,1,0,0,0 --epsilon 2
  check epsilon_old_name_checked 2 "^cfinspect: --epsilon: 'nan' is not a finite number" -- "$CFINSPECT" "$G" --pose 20,10.3,5,1,0,0,0 --epsilon nan
  # Outputs.
  cp "$G" g.json
  check dot_device 1 "^cfinspect: writing DOT '/dev/full': is a character device; output files must be regular files" -- "$CFINSPECT" g.json --dot /dev/full
  check dot_fifo 1 "^cfinspect: writing DOT 'out_fifo.json': is a FIFO" -- "$CFINSPECT" g.json --dot out_fifo.json
  check dot_directory 1 "^cfinspect: writing DOT 'dir.json': is a directory" -- "$CFINSPECT" g.json --dot dir.json
  check dot_over_input 1 "^cfinspect: writing DOT 'g.json': is an input of this run; refusing to overwrite it" -- "$CFINSPECT" g.json --dot g.json
  check dot_same_as_html 1 "^cfinspect: writing HTML './new.dot': is also the output 'new.dot'; each output needs its own file" -- "$CFINSPECT" g.json --dot new.dot --html ./new.dot
  absent dot_same_as_html_nothing_written new.dot
  if cmp -s g.json "$G"; then report dot_input_intact 1 ""; else report dot_input_intact 0 "g.json changed"; fi
  echo old >target.dot
  ln -s target.dot link.dot
  check dot_symlink 0 "^$" -- "$CFINSPECT" g.json --dot link.dot
  if [[ -L link.dot ]] && grep -q '^digraph' target.dot; then report dot_symlink_followed 1 ""; else report dot_symlink_followed 0 "the link was replaced or its target not written"; fi
  # False graphs (docs/bad-input.md, row 58): every witness is re-checked with cfgen's verify
  # (when cfinspect was built with it: not in the CGAL-free sanitizer build).
  if "$CFINSPECT" "$GEN" | grep -q "witnesses verified"; then
    python3 - "$GEN" <<'PY'
import json, sys
src = json.load(open(sys.argv[1]))
def save(name, edit):
    g = json.loads(json.dumps(src)); edit(g); json.dump(g, open(name, 'w'))
def inside(g): g['cfs'][0]['witness'] = {'R': [[1, 0, 0], [0, 1, 0], [0, 0, 1]], 't': [60, 10, 40]}
def far(g): g['cfs'][0]['witness']['t'] = [1e308, 0, 0]
def opposite(g):  # the cube's faces 0 (-z) and 1 (+z) on the L-block at once
    c = dict(g['cfs'][0]); c['id'] = len(g['cfs'])
    c['pcs'] = [{'type': 'f-f', 'a': 0, 'b': 2}, {'type': 'f-f', 'a': 1, 'b': 3}]
    for k in ('dof', 'translation_dof', 'pure_rotation', 'planes'): c.pop(k, None)
    g['cfs'].append(c)
def dof(g): g['cfs'][574]['dof'] = 2
for name, edit in (('inside.json', inside), ('far.json', far), ('opposite.json', opposite), ('dof.json', dof)):
    save(name, edit)
PY
    check witness_inside_b 1 "^cfinspect: 'inside.json' at /cfs/0: CF 0 \{f-f:0:0\}: witness refused by verify: .* \(1 of 1390 CFs fail the witness check\)$" -- "$CFINSPECT" inside.json
    check witness_far 1 "^cfinspect: 'far.json' at /cfs/0: CF 0 \{f-f:0:0\}: witness puts A 1e\+308 mm beyond touching B \(1 of 1390" -- "$CFINSPECT" far.json
    check witness_opposite_faces 1 "^cfinspect: 'opposite.json' at /cfs/1390: CF 1390 \{f-f:0:2;f-f:1:3\}: witness refused by verify: " -- "$CFINSPECT" opposite.json
    check witness_dof 1 "^cfinspect: 'dof.json' at /cfs/574: CF 574 \{f-f:0:4;f-f:2:5\}: dof = 2, but 1 at the witness" -- "$CFINSPECT" dof.json
    check witness_check_with_query 1 "^cfinspect: 'far.json' at /cfs/0: " -- "$CFINSPECT" far.json --cf 3
    check witness_fast_skips 0 "^$" -- "$CFINSPECT" far.json --fast
    check witness_fast_verify 1 "^cfinspect: 'far.json' at /cfs/0: " -- "$CFINSPECT" far.json --fast --verify
  fi
  # A graph without CF: valid, with a warning, exit 0.
  python3 -c "
import json; g = json.load(open('$G')); g['cfs'] = []; g['transitions'] = []
json.dump(g, open('empty.json', 'w'))"
  check no_cf_warning 0 "^cfinspect: warning: the graph has no CF" -- "$CFINSPECT" empty.json
  absent cfinspect_nothing_left
fi

# ---------------------------------------------------------------------------------------
if [[ "$group" == cfreplay ]]; then
  run=("$CFREPLAY" --graph "$G" --trajectory "$P")
  check graph_fifo 1 "^cfreplay: reading 'fifo.json': cannot open: is a FIFO \(named pipe\), not a regular file" -- "$CFREPLAY" --graph fifo.json --trajectory "$P" -o o.csv
  check path_escapes 1 "^cfreplay: reading '\\\\x1B\]0;title\\\\x07g\.json': cannot open: no such file" -- "$CFREPLAY" --graph $'\e]0;title\ag.json' --trajectory "$P" -o o.csv
  check trajectory_fifo 1 "^cfreplay: fifo.csv: cannot open the trajectory: is a FIFO \(named pipe\), not a regular file" -- "$CFREPLAY" --graph "$G" --trajectory fifo.csv -o o.csv
  check trajectory_directory 1 "^cfreplay: dir.csv: cannot open the trajectory: is a directory, not a regular file" -- "$CFREPLAY" --graph "$G" --trajectory dir.csv -o o.csv
  head -c 3000 /dev/urandom >garbage.csv
  check trajectory_binary_garbage 1 "^cfreplay: garbage.csv:[0-9]+: " -- "$CFREPLAY" --graph "$G" --trajectory garbage.csv -o o.csv
  printf 't,tx,ty,tz,qw,qx,qy,qz\n0,1,2,\x01\x9b[31m,1,0,0,0\n' >escape.csv
  check trajectory_escape_sequence 1 "^cfreplay: escape.csv:2: column 'tz' is not a finite number: '\\\\x01\\\\x9B\[31m'" -- "$CFREPLAY" --graph "$G" --trajectory escape.csv -o o.csv
  # Decimal numbers only; a subnormal time is a number; times 1e-7 s apart stay distinct.
  printf 't,tx,ty,tz,qw,qx,qy,qz\n0,0x14,10.3,5,1,0,0,0\n' >hex.csv
  check trajectory_hex_float 1 "^cfreplay: hex.csv:2: column 'tx' is not a decimal number: '0x14'" -- "$CFREPLAY" --graph "$G" --trajectory hex.csv -o o.csv
  printf 't,tx,ty,tz,qw,qx,qy,qz\n0,20,10.3,5,1,0,0,0\n5e-324,20,10.3,5,1,0,0,0\n' >subnormal.csv
  check trajectory_subnormal_time 0 "^cfreplay: 2 ticks" -- "$CFREPLAY" --graph "$G" --trajectory subnormal.csv -o subnormal_out.csv
  printf 't,tx,ty,tz,qw,qx,qy,qz\n0,20,10.3,5,1,0,0,0\n1e-7,20,10.3,5,1,0,0,0\n2e-7,20,10.3,5,1,0,0,0\n' >fine.csv
  check trajectory_fine_times 0 "^cfreplay: 3 ticks" -- "$CFREPLAY" --graph "$G" --trajectory fine.csv -o fine_out.csv
  if [[ $(cut -d, -f1 fine_out.csv | tr '\n' ' ') == "t 0 1e-07 2e-07 " ]]; then report fine_times_distinct 1 ""; else report fine_times_distinct 0 "t column: $(cut -d, -f1 fine_out.csv | tr '\n' ' ')"; fi
  rm -f subnormal_out.csv fine_out.csv
  printf 't,tx,ty,tz,qw,qx,qy,qz\n0,20,10.3,5,0.7071,0.7071,0,0\n' >q4.csv
  check quaternion_4_decimals 0 "^cfreplay: 1 tick -> " -- "$CFREPLAY" --graph "$G" --trajectory q4.csv -o q4_out.csv
  printf 't,tx,ty,tz,qw,qx,qy,qz\n0,20,10.3,5,1,0.1,0,0\n' >q_bad.csv
  check quaternion_not_unit 1 "^cfreplay: q_bad.csv:2: the quaternion \(qw,qx,qy,qz\) has norm 1.00498756, not 1 within 0.001" -- "$CFREPLAY" --graph "$G" --trajectory q_bad.csv -o o.csv
  python3 -c "import sys; sys.stdout.buffer.write(b'\xa1\x61x' + b'\x81' * 100000 + b'\xf6')" >deep.cbor
  check cbor_deep_nesting 1 "^cfreplay: reading 'deep.cbor': not valid CBOR: nesting deeper than 256 levels" -- "$CFREPLAY" --graph deep.cbor --trajectory "$P" -o o.csv
  # Options: finite and in range.
  for opt in --mass-kg --contact-stiffness-N-per-mm --kp-N-per-mm --mu-static --mu-kinetic \
    --epsilon-mm --hold-fcy-threshold-N --interpolation-time-constant-s; do
    check "cfreplay${opt}_nan" 2 "^cfreplay: ${opt}: 'nan' is not a finite number" -- "${run[@]}" -o o.csv "$opt" nan
    check "cfreplay${opt}_inf" 2 "^cfreplay: ${opt}: 'inf' is not a finite number" -- "${run[@]}" -o o.csv "$opt" inf
  done
  check cfreplay_moment_point_nan 2 "^cfreplay: --moment-point-A: 'nan' is not a finite number" -- "${run[@]}" -o o.csv --moment-point-A nan 0 0
  check cfreplay_epsilon_huge 2 "^cfreplay: --epsilon-mm: '1e308' is outside \[1e-06, 1000\]" -- "${run[@]}" -o o.csv --epsilon-mm 1e308
  check cfreplay_stiffness_zero 2 "^cfreplay: --contact-stiffness-N-per-mm: '0' is outside \(0, 1e\+09\]" -- "${run[@]}" -o o.csv --contact-stiffness-N-per-mm 0
  check cfreplay_mass_negative 2 "^cfreplay: --mass-kg: '-1' is outside \[0, 1e\+06\]" -- "${run[@]}" -o o.csv --mass-kg -1
  # The names before the options took the Python keywords': still taken, checked the same,
  # with a warning naming the new one.
  check cfreplay_old_name_checked 2 "^cfreplay: --mu: 'nan' is not a finite number" -- "${run[@]}" -o o.csv --mu nan
  check cfreplay_old_names_warn 0 "^cfreplay: warning: --mu is now --mu-static; the old name goes in the next release" -- "${run[@]}" -o o.csv --mu 0.6 --friction per-tick --moment-ref centroid
  check cfreplay_old_values_warn 0 "^cfreplay: warning: 'per-tick' is now 'per_tick'" -- "${run[@]}" -o o.csv --friction per-tick
  rm -f o.csv
  # Options checked together, before the work.
  check cfreplay_moment_ref_and_point 2 "^cfreplay: --moment-reference a_origin contradicts --moment-point-A, which sets the moment's reference point; give one" -- "${run[@]}" -o o.csv --moment-reference a_origin --moment-point-A 1 2 3
  check cfreplay_moment_ref_point_alone 2 "^cfreplay: --moment-reference a_point needs --moment-point-A X Y Z" -- "${run[@]}" -o o.csv --moment-reference a_point
  check cfreplay_mu_d_above_default_mu 2 "^cfreplay: --mu-kinetic 0.9 is above --mu-static 0.7 \(the default\): kinetic friction cannot exceed static friction; give --mu-kinetic at most --mu-static" -- "${run[@]}" -o o.csv --mu-kinetic 0.9
  check cfreplay_mu_below_default_mu_d 2 "^cfreplay: --mu-kinetic 0.08 \(the default\) is above --mu-static 0.05" -- "${run[@]}" -o o.csv --mu-static 0.05
  rm -f o.csv
  absent cfreplay_contradictions_no_output o.csv
  # Outputs.
  cp "$P" in.csv
  check out_device 1 "^cfreplay: writing '/dev/full': is a character device; output files must be regular files" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o /dev/full
  check plot_device 1 "^cfreplay: writing '/dev/null': is a character device" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o o.csv --plot /dev/null
  check out_fifo 1 "^cfreplay: writing 'out_fifo.csv': is a FIFO" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o out_fifo.csv
  check out_directory 1 "^cfreplay: writing 'dir.csv': is a directory" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o dir.csv
  check out_is_trajectory 1 "^cfreplay: writing 'in.csv': is an input of this run; refusing to overwrite it" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o in.csv
  check plot_is_trajectory 1 "^cfreplay: writing 'in.csv': is an input of this run" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o o.csv --plot in.csv
  check out_same_as_plot 1 "^cfreplay: writing 'same.csv': is also the output 'same.csv'" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o same.csv --plot same.csv
  check out_same_as_plot_dot_slash 1 "^cfreplay: writing './new_same.csv': is also the output 'new_same.csv'; each output needs its own file" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o new_same.csv --plot ./new_same.csv
  absent out_same_as_plot_nothing_written new_same.csv
  check plot_no_directory 1 "^cfreplay: writing 'no/such/p.svg': the directory 'no/such' does not exist" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o o.csv --plot no/such/p.svg
  if cmp -s in.csv "$P"; then report out_input_intact 1 ""; else report out_input_intact 0 "in.csv changed"; fi
  absent cfreplay_no_csv_left o.csv same.csv
  echo old >target.csv
  ln -s target.csv link.csv
  check out_symlink 0 "^cfreplay: 2 ticks" -- "$CFREPLAY" --graph "$G" --trajectory in.csv -o link.csv
  if [[ -L link.csv ]] && grep -q '^t,cf,pcs' target.csv; then report out_symlink_followed 1 ""; else report out_symlink_followed 0 "the link was replaced or its target not written"; fi
  absent cfreplay_nothing_left o.csv
fi

printf '%s: %d checks passed, %d failed\n' "$group" "$pass" "$fail"
[[ $fail == 0 ]]
