"""The --help of the nsgraph.models commands: every option with its default, as `nsgraph
<command> --help` shows them (required options and plain flags have none to show)."""
import argparse


class DefaultsHelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    def _get_help_string(self, action):
        if action.required or action.default is None or action.default is False or action.default is argparse.SUPPRESS:
            return action.help
        return super()._get_help_string(action)
