#!/usr/bin/env bash
# Runs the commands of a Markdown page as a reader would, and fails when one
# of them does not do what the page says.
#
#   run_doc_commands.sh PAGE.md SOURCE_DIR TOOLS_DIR WORK_DIR MIN_BLOCKS
#
# A fenced ```sh block is run when the line just before it is a marker:
#
#   <!-- test -->                                   exit 0 expected
#   <!-- test: exit=1 -->                           that exit code expected
#   <!-- test: creates=fit/result.yaml,fit/a.csv --> these files must exist after it
#
# Blocks run in page order, each with `bash -e` in WORK_DIR (emptied first),
# with DWELLFIT set to SOURCE_DIR and TOOLS to TOOLS_DIR, as the page asks the
# reader to set them. Fewer than MIN_BLOCKS marked blocks is a failure too,
# so a page that lost its markers does not pass by running nothing.
set -u
page=$1 source_dir=$2 tools_dir=$3 work_dir=$4 min_blocks=$5
[[ -f $page ]] || { echo "no page $page"; exit 1; }
rm -rf "$work_dir" && mkdir -p "$work_dir/.blocks" || exit 1

# Split the page: block N's commands into .blocks/N.sh, its marker into N.marker.
awk -v dir="$work_dir/.blocks" '
  /^<!-- test(:.*)? -->$/ { marker = $0; next }
  /^```sh$/ && marker != "" { n++; inblock = 1; print marker > (dir "/" n ".marker"); marker = ""; next }
  inblock && /^```$/ { inblock = 0; next }
  inblock { print > (dir "/" n ".sh"); next }
  { marker = "" }
' "$page"

blocks=$(ls "$work_dir/.blocks" | grep -c '\.sh$')
if (( blocks < min_blocks )); then
  echo "FAIL: $page has $blocks marked sh blocks, expected at least $min_blocks"
  exit 1
fi

failed=0
for ((n = 1; n <= blocks; n++)); do
  marker=$(cat "$work_dir/.blocks/$n.marker")
  expected_exit=0
  [[ $marker =~ exit=([0-9]+) ]] && expected_exit=${BASH_REMATCH[1]}
  creates=""
  [[ $marker =~ creates=([^ ]+) ]] && creates=${BASH_REMATCH[1]//,/ }
  echo "---- block $n (expects exit $expected_exit):"
  cat "$work_dir/.blocks/$n.sh"
  (cd "$work_dir" && DWELLFIT="$source_dir" TOOLS="$tools_dir" \
     bash -e "$work_dir/.blocks/$n.sh") > "$work_dir/.blocks/$n.log" 2>&1
  status=$?
  tail -n 15 "$work_dir/.blocks/$n.log"
  if (( status != expected_exit )); then
    echo "FAIL: block $n exited $status, expected $expected_exit"
    failed=1
  fi
  for file in $creates; do
    if [[ ! -s $work_dir/$file ]]; then
      echo "FAIL: block $n did not create $file"
      failed=1
    fi
  done
done
(( failed == 0 )) && echo "all $blocks blocks of $page ran as the page says"
exit $failed
