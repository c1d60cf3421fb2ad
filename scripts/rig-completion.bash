# Bash completion for `rig`; `cmake --install` puts it where bash-completion
# loads it on demand (share/bash-completion/completions/rig). Without an
# install: `source scripts/rig-completion.bash`.
#
# The words come from the rig's own --help at each completion (subcommands,
# options), so they are always those of the rig being completed; case files and
# output folders complete as paths.

# The subcommands or the options (by $2: "commands" or "options") listed in
# `RIG PATH... --help`, one per line.
_rig_help_words() {
    local what=$1 rig=$2
    shift 2
    "$rig" "$@" --help 2>/dev/null | awk -v what="$what" '
        /^[A-Za-z][A-Za-z ]*:$/ { section = $0; next }
        what == "commands" && section == "Subcommands:" && /^  [a-z]/ { print $1 }
        what == "options" && section == "Options:" && /^  -/ {
            n = split($1, names, ",")
            for (i = 1; i <= n; i++) print names[i]
        }'
}

_rig() {
    local cur=${COMP_WORDS[COMP_CWORD]}
    local rig=${COMP_WORDS[0]}
    # The subcommands typed so far (rig nmea decode ...): each word that is a
    # subcommand of the one before it.
    local path=() word
    local i
    for ((i = 1; i < COMP_CWORD; i++)); do
        word=${COMP_WORDS[i]}
        [[ $word == -* ]] && continue
        if _rig_help_words commands "$rig" "${path[@]}" | grep -qxF -- "$word"; then
            path+=("$word")
        fi
    done
    local words
    if [[ $cur == -* ]]; then
        words=$(_rig_help_words options "$rig" "${path[@]}")
        mapfile -t COMPREPLY < <(compgen -W "$words" -- "$cur")
        return
    fi
    words=$(_rig_help_words commands "$rig" "${path[@]}")
    if [[ -n $words ]]; then
        mapfile -t COMPREPLY < <(compgen -W "$words" -- "$cur")
        return
    fi
    # A command's arguments: case files, folders of them, run folders, traces.
    compopt -o filenames 2>/dev/null
    mapfile -t COMPREPLY < <(compgen -f -- "$cur")
}

complete -F _rig rig
