#!/usr/bin/env bash
# icef export end to end: a tiny synthetic dataset, tiny models trained for a few steps, exported as
# GLB; the Khronos glTF validator (installed by scripts/install-deps.sh) finds no errors; the morph
# targets carry the expression names; a model without a face-model prior exports a static mesh and
# says so; nerface and a wrong file name are refused with one line and nothing written.
set -euo pipefail
ICEF="$1"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
VALIDATOR=/usr/local/share/icef/gltf-validator
[ -s "$VALIDATOR/index.js" ] || fail "no glTF validator in $VALIDATOR (scripts/install-deps.sh installs it)"

"$ICEF" synth --out "$WORK/data" --identity-seed 2 --k 3 --res 32 --test-views 1 --novel-per-tier 1 \
  --supersample 1 --threads 2 > /dev/null
TINY=(--set model.static_field.grid.num_levels=4 --set model.static_field.grid.log2_table_size=10 --set model.static_field.grid.finest_resolution=32
      --set model.static_field.density_hidden=16 --set "model.static_field.color_hidden=[16]" --set "model.deformation.hidden=[16,16]"
      --set model.sampler.num_samples=16 --set model.occupancy.resolution=16 --set train.batch_rays=256)
for method in icef-prior icef nerface; do
  "$ICEF" train "$WORK/data" --out "$WORK/$method" --method "$method" --steps 30 --threads 2 --quiet "${TINY[@]}" \
    > /dev/null || fail "icef train --method $method exited $?"
done

# The surface at the density the model's renders of its training views put it (the default).
"$ICEF" export "$WORK/icef-prior" --out "$WORK/avatar.glb" --resolution 40 --triangles 4000 --threads 2 \
  > "$WORK/out.txt" 2> "$WORK/err.txt" || fail "icef export exited $?: $(cat "$WORK/err.txt")"
cat "$WORK/out.txt"
grep -Eq "^wrote .*avatar.glb: [0-9]+ vertices, [0-9]+ triangles at density [0-9.e+-]+, 11 morph targets" "$WORK/out.txt" \
  || fail "no summary line"

node - "$WORK/avatar.glb" "$VALIDATOR" <<'JS' || fail "the GLB does not validate"
const fs = require('fs');
const [file, validatorDir] = process.argv.slice(2);
const validator = require(validatorDir);
const bytes = new Uint8Array(fs.readFileSync(file));
validator.validateBytes(bytes).then((report) => {
  const issues = report.issues;
  for (const m of issues.messages.filter((m) => m.severity === 0).slice(0, 10))
    console.error(`${m.code}: ${m.message} (${m.pointer})`);
  if (issues.numErrors !== 0) { console.error(`${issues.numErrors} errors`); process.exit(1); }
  // The JSON chunk: morph targets named in mesh.extras.targetNames, one per target.
  const jsonLength = bytes[12] | (bytes[13] << 8) | (bytes[14] << 16) | (bytes[15] << 24);
  const gltf = JSON.parse(Buffer.from(bytes.slice(20, 20 + jsonLength)).toString('utf8'));
  const mesh = gltf.meshes[0], names = mesh.extras.targetNames;
  if (names.length !== mesh.primitives[0].targets.length || names.length !== mesh.weights.length) {
    console.error('targetNames do not match the targets'); process.exit(1);
  }
  if (!names.includes('jaw_open')) { console.error(`no jaw_open target: ${names}`); process.exit(1); }
  console.log(`validator: 0 errors, ${issues.numWarnings} warnings; targets ${names.join(',')}`);
}).catch((e) => { console.error(e); process.exit(1); });
JS

"$ICEF" export "$WORK/icef" --out "$WORK/static.glb" --resolution 32 --density 0.02 --threads 2 > "$WORK/out.txt" \
  || fail "static export exited $?"
grep -q "0 morph targets" "$WORK/out.txt" && grep -q "^note: .*no face-model prior" "$WORK/out.txt" \
  || fail "the static export does not say so: $(cat "$WORK/out.txt")"

for bad in "$WORK/nerface --out $WORK/n.glb" "$WORK/icef-prior --out $WORK/a.gltf"; do
  set +e
  # shellcheck disable=SC2086
  "$ICEF" export $bad > /dev/null 2> "$WORK/err.txt"; code=$?
  set -e
  [ "$code" -eq 1 ] && [ "$(wc -l < "$WORK/err.txt")" -eq 1 ] || fail "export $bad: exit $code: $(cat "$WORK/err.txt")"
done
[ ! -e "$WORK/n.glb" ] && [ ! -e "$WORK/a.gltf" ] || fail "a refused export left a file"
echo "export_test: ok"
