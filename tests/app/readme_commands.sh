#!/usr/bin/env bash
# Runs every command shown in a fenced ```sh block of README.md, every page of docs/ (but the
# decision records of docs/decisions/, which keep history) and protocols/README.md on the bundled
# data, in order, one scratch folder per document (so a document's commands see each other's
# files). Under the sanitizer build this makes every documented command a memory
# check. Commands that need hardware, a server or a placeholder filled in are
# skipped with the reason printed; a crash, a sanitizer report, a timeout or a non-zero exit of
# any other command fails the test.
#   readme_commands.sh <underfoot> <source dir> <work dir>
set -uo pipefail
underfoot="$(readlink -f "$1")"
src="$(readlink -f "$2")"
work="$3"
rm -rf "$work" && mkdir -p "$work" || exit 1
work="$(readlink -f "$work")"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}:abort_on_error=1"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1}:halt_on_error=1:abort_on_error=1"

# Why a command cannot run here (empty: it runs). Patterns are matched against the command.
skip_reason() {
    local c="$1"
    case "$c" in
    *scripts/setup.sh* | *scripts/test.sh* | *scripts/package.sh* | cmake* | ninja* | .ci/run* | *"git clone"*) echo "builds or tests the project (this test runs inside that)" ;;
    *fetch-recordings.sh*) echo "downloads recorded footsteps from Debian's archive (setup.sh does; the realism tests use them)" ;;
    jackd* | *"export JACK_"*) echo "starts a JACK server (the live tests do this with their own server)" ;;
    socat*) echo "starts a pseudo-terminal pair that runs until stopped (tests/live do this with their own)" ;;
    arduino-cli*) echo "flashes the shoes' Arduino (needs the board and arduino-cli)" ;;
    *"apt-get install"* | *"dpkg -i"*) echo "installs packages on this machine (tests/package install them in a clean root)" ;;
    *"underfoot devices"* | *"underfoot live"* | *" --live"*) echo "needs an audio device (JACK server)" ;;
    *"--serial /dev/"* | *"underfoot sensors"*) echo "needs the FSR shoes on a serial port" ;;
    *"--osc "*) echo "needs gyroscopes sending OSC" ;;
    *"underfoot analyze --study online.db"*) echo "needs answers: the participants take the test in their browsers first (tests/web do)" ;;
    *"underfoot serve "*) echo "starts the web server and runs until stopped (tests/web run it on loopback)" ;;
    *"my_recordings/"* | *"recordings remove --source mylab"*) echo "needs your own recorded footsteps in my_recordings/ (the document says: record them first)" ;;
    *"my_floor/"*) echo "needs your own recorded footsteps in my_floor/ (the document says: record them first)" ;;
    *"wading_realism.toml -o clips3"* | *"--clips clips3"* | *"--study wading3.db"*"--format html"*) echo "needs the lab's own recordings in clips3/real/ (the document says: put them there first)" ;;
    *"underfoot replay --study exp2.db --participant P01 --trial 3"*) echo "needs P01 to have answered trial 3 in the interactive session above (stdin is empty here)" ;;
    *) echo "" ;;
    esac
}

# Interactive commands read answers from stdin; here stdin is empty, so they must end cleanly
# (any exit status below 128 without a sanitizer report) without answering.
interactive() {
    case "$1" in
    *"underfoot session"*"--participant"*) return 0 ;;
    *) return 1 ;;
    esac
}

# Bundled data a document's examples name as if the reader had it.
prepare() {
    local dir="$1"
    ln -s "$src/protocols" "$dir/protocols"
    cp "$src/engine/data/grf/heel_1.wav" "$dir/step.wav" # `render --grf step.wav`
}

# Files a document asks the reader to write: a fenced block opened as ```toml file=NAME (any
# language) is written to NAME in the document's scratch folder before its commands run.
write_files() {
    awk -v dir="$2" '
        /^```[A-Za-z]+ file=[A-Za-z0-9_.\/-]+[[:space:]]*$/ {
            name = $2; sub(/^file=/, "", name)
            if (name ~ /\.\./ || name ~ /^\//) { print "bad file name " name > "/dev/stderr"; exit 1 }
            out = dir "/" name; printf "" > out; inside = 1; next
        }
        /^```/ { if (inside) close(out); inside = 0; next }
        inside { print >> out }' "$1"
}

# Fenced sh/bash blocks of one file, one command per line (continuations joined, comments cut).
commands_of() {
    awk '
        /^```(sh|bash|shell)[[:space:]]*$/ { inside = 1; next }
        /^```/ { inside = 0; next }
        inside {
            line = $0
            if (line ~ /^[[:space:]]*#/) next
            if (line ~ /\\[[:space:]]*$/) { sub(/\\[[:space:]]*$/, "", line); acc = acc line " "; next }
            line = acc line; acc = ""
            # cut a trailing comment: the first " #" outside quotes
            q = ""; cut = 0
            for (i = 1; i <= length(line); i++) {
                ch = substr(line, i, 1)
                if (q == "" && (ch == "\"" || ch == "'\''")) q = ch
                else if (q != "" && ch == q) q = ""
                else if (q == "" && ch == "#" && i > 1 && substr(line, i - 1, 1) ~ /[[:space:]]/) { cut = i; break }
            }
            if (cut) line = substr(line, 1, cut - 1)
            gsub(/^[[:space:]]+|[[:space:]]+$/, "", line)
            if (line != "") print line
        }' "$1"
}

fail=0 ran=0 skipped=0
docs=("$src/README.md")
while IFS= read -r d; do docs+=("$d"); done < <(find "$src/docs" -name '*.md' -not -path '*/decisions/*' | sort)
docs+=("$src/protocols/README.md")
for doc in "${docs[@]}"; do
    [ -f "$doc" ] || continue
    rel="${doc#$src/}"
    name="${rel%.md}"
    name="${name//\//_}"
    dir="$work/$name"
    mkdir -p "$dir" && prepare "$dir"
    write_files "$doc" "$dir" || { echo "FAIL ${doc#$src/}: a file block could not be written"; fail=1; }
    n=0
    while IFS= read -r cmd; do
        n=$((n + 1))
        reason="$(skip_reason "$cmd")"
        if [ -n "$reason" ]; then
            echo "skip ${doc#$src/} #$n: $cmd"
            echo "     reason: $reason"
            skipped=$((skipped + 1))
            continue
        fi
        run="$(printf '%s' "$cmd" | sed -E "s#(^|[|;&] *)(build/app/cli/)?underfoot #\1\"$underfoot\" #g")"
        ran=$((ran + 1))
        log="$dir/cmd_$n.log"
        (cd "$dir" && timeout 600 bash -c "$run" < /dev/null > "$log" 2>&1)
        st=$?
        bad=0
        if grep -qE "ERROR: AddressSanitizer|ERROR: LeakSanitizer|runtime error:" "$log"; then
            bad=1
        elif [ $st -ge 124 ]; then
            bad=1
        elif [ $st != 0 ] && ! interactive "$cmd"; then
            bad=1
        fi
        if [ $bad = 1 ]; then
            echo "FAIL ${doc#$src/} #$n (status $st): $cmd"
            tail -40 "$log" | sed 's/^/     | /'
            fail=1
        else
            echo "ok   ${doc#$src/} #$n (status $st): $cmd"
        fi
    done < <(commands_of "$doc")
done
echo "== $ran documented command(s) run, $skipped skipped"
[ $ran -gt 0 ] || { echo "FAIL: no command found in the documents"; exit 1; }
exit $fail
