#!/bin/sh
# Runs one command in a tmux pane for wizard_terminal_test: prints its exit code, then whether the
# terminal is back in canonical mode (the wizard must undo its raw mode on every exit path), and
# keeps the pane open so that the test can read the last screen.
# Ctrl-C sent to the pane reaches the whole foreground group: this shell must outlive it (a caught
# signal, unlike an ignored one, is not inherited by the command).
trap 'true' INT
"$@"
echo "WIZARD_EXIT=$?"
if stty -a | grep -q -- '-icanon'; then echo "TTY_RAW"; else echo "TTY_icanon"; fi
sleep 60
