#!/usr/bin/env bash
# CI check (issue 8, DEVELOPERS.md "Outputs"): every file hairvox writes goes
# through writeFileAtomically(), whose writer callback receives the temporary
# path as `tmp`. Flags any output stream in the libraries or the CLI that is
# opened on another path (std::ofstream/fstream, fopen, Imf::OutputFile,
# png_image_write_to_file, openvdb::io::File::write).
set -euo pipefail
cd "$(dirname "$0")/.."
dirs=(core strands geometry shading voxelize transmittance film render pipeline bench/sweep cli)
opens='std::ofstream [A-Za-z_]+\(|std::fstream|fopen\(|OutputFile [A-Za-z_]+\(|png_image_write_to_file\(|io::File [A-Za-z_]+\('
bad=$(grep -rnE "$opens" "${dirs[@]}" --include='*.cpp' --include='*.h' |
      grep -vE "\((&image, )?tmp[.,)]" || true)
# openvdb::io::File is also how grids are read: only a File that writes counts.
bad=$(printf '%s\n' "$bad" | while IFS= read -r line; do
  [[ -z $line ]] && continue
  if [[ $line == *"io::File "* ]]; then
    file=${line%%:*}; rest=${line#*:}; n=${rest%%:*}
    name=$(sed -n "${n}p" "$file" | grep -oE 'io::File [A-Za-z_]+' | awk '{print $2}')
    sed -n "${n},$((n + 5))p" "$file" | grep -q "$name\.write(" || continue
  fi
  echo "$line"
done)
if [[ -n $bad ]]; then
  echo "ci-check-outputs: outputs not written through writeFileAtomically():" >&2
  echo "$bad" >&2
  exit 1
fi
echo "ci-check-outputs: every output goes through writeFileAtomically()"
