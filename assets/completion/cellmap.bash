# bash completion for cellmap. The commands, options and model names come
# from cellmap itself (`cellmap --help`, `cellmap help COMMAND`, `cellmap
# models`), so the completion knows what the installed cellmap knows.
# Installed by `cmake --install` as share/bash-completion/completions/cellmap.

_cellmap()
{
    local cur prev cmd words
    cur=${COMP_WORDS[COMP_CWORD]}
    prev=${COMP_WORDS[COMP_CWORD-1]}
    cmd=${COMP_WORDS[1]}
    local cm=${COMP_WORDS[0]}
    if [ "$COMP_CWORD" -eq 1 ]; then
        words="help $("$cm" --help 2> /dev/null | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p')"
        COMPREPLY=($(compgen -W "$words" -- "$cur"))
        return
    fi
    if [ "$cmd" = help ] && [ "$COMP_CWORD" -eq 2 ]; then
        words=$("$cm" --help 2> /dev/null | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p')
        COMPREPLY=($(compgen -W "$words" -- "$cur"))
        return
    fi
    case $prev in
    --model)
        words=$("$cm" models 2> /dev/null | sed -n 's/^\([a-z][a-z0-9-]*\)$/\1/p')
        COMPREPLY=($(compgen -W "$words" -- "$cur"))
        return ;;
    --png|--csv|--db|--groups|--cells|--flat|--runs-csv|--events|--spectrum|--branches|--curves|--input)
        COMPREPLY=($(compgen -f -- "$cur"))
        return ;;
    esac
    if [[ $cur == -* ]]; then
        words=$("$cm" help "$cmd" 2> /dev/null | grep -o -- '--[a-z][a-z0-9-]*' | sort -u)
        COMPREPLY=($(compgen -W "$words" -- "$cur"))
        return
    fi
    COMPREPLY=($(compgen -f -- "$cur")) # .cmdb files, scripts
}
complete -o filenames -F _cellmap cellmap
