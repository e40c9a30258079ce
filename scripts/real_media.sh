#!/usr/bin/env bash
# The real media that `icef bench --real` and the validation decisions use: public clips and photos
# from the repositories of face-reconstruction projects. Their licences mostly forbid
# redistribution, so they are never committed: this script copies them out of local git snapshots
# of those repositories into a cache, and writes SOURCES.tsv there naming the repository, commit
# and path of every file (the committed reports quote it).
#
#   scripts/real_media.sh --from DIR   copy from snapshots under DIR (DIR/<owner>+<repo>/repo, bare git
#                                      repositories; e.g. snapshots fetched at development time)
#   scripts/real_media.sh --list       print the cached sources, one per line (what --real takes)
#
# The cache: $ICEF_REAL_MEDIA, else ~/.cache/icef/real_media. Nothing is downloaded.
set -euo pipefail

CACHE="${ICEF_REAL_MEDIA:-$HOME/.cache/icef/real_media}"

# name | repository | path in it (a file, or a folder of photos) | role
MEDIA=(
  "smirk-skarsgard|georgeretsi/smirk|samples/skarsgard.mp4|test"
  "smirk-dafoe|georgeretsi/smirk|samples/dafoe.mp4|validation"
  "cap4d-felix|felixtaubner/cap4d|examples/input/felix/images/cam0|test"
  "cap4d-animation|felixtaubner/cap4d|examples/input/animation/example_video.mp4|validation"
)

usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }

case "${1:-}" in
  --from)
    [ $# -eq 2 ] || usage
    from="$2"
    mkdir -p "$CACHE"
    tmp=$(mktemp "$CACHE/.SOURCES.XXXXXX")
    printf 'name\trole\trepository\tcommit\tpath\n' >"$tmp"
    for entry in "${MEDIA[@]}"; do
      IFS='|' read -r name repo path role <<<"$entry"
      git_dir="$from/${repo/\//+}/repo"
      if [ ! -d "$git_dir" ]; then
        echo "real_media: $name: no snapshot of $repo at $git_dir (skipped)" >&2
        continue
      fi
      commit=$(git --git-dir="$git_dir" rev-parse HEAD)
      type=$(git --git-dir="$git_dir" cat-file -t "HEAD:$path" 2>/dev/null || true)
      case "$type" in
        blob)
          out="$CACHE/$name.${path##*.}"
          git --git-dir="$git_dir" show "HEAD:$path" >"$out.part" && mv "$out.part" "$out" ;;
        tree)
          out="$CACHE/$name"
          rm -rf "$out.part" && mkdir -p "$out.part"
          git --git-dir="$git_dir" ls-tree --name-only "HEAD:$path" | while read -r f; do
            git --git-dir="$git_dir" show "HEAD:$path/$f" >"$out.part/$f"
          done
          rm -rf "$out" && mv "$out.part" "$out" ;;
        *)
          echo "real_media: $name: $repo has no $path at $commit (skipped)" >&2
          continue ;;
      esac
      printf '%s\t%s\t%s\t%s\t%s\n' "$name" "$role" "$repo" "$commit" "$path" >>"$tmp"
      echo "real_media: $name <- $repo@${commit:0:12}:$path"
    done
    mv "$tmp" "$CACHE/SOURCES.tsv" ;;
  --list)
    [ -f "$CACHE/SOURCES.tsv" ] || { echo "real_media: no cache at $CACHE (run with --from first)" >&2; exit 1; }
    role="${2:-}"
    tail -n +2 "$CACHE/SOURCES.tsv" | while IFS=$'\t' read -r name r repo commit path; do
      [ -z "$role" ] || [ "$r" = "$role" ] || continue
      if [ -d "$CACHE/$name" ]; then echo "$CACHE/$name"; else echo "$CACHE/$name.${path##*.}"; fi
    done ;;
  *) usage ;;
esac
