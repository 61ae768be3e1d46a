"""``avar datasets``: list the shipped IMU data sets, or summarize and plot one."""

from __future__ import annotations

import argparse

from avar.cli.common import InputFileError, UsageError, format_table
from avar.cli.outputs import plan_outputs, report


def run(args: argparse.Namespace) -> int:
    from avar.io import datasets

    if args.name is None:
        if args.plot:
            raise UsageError("--plot needs a data set name, e.g. 'avar datasets navchip_av --plot navchip.png'")
        print(format_table(datasets.list()))
        return 0
    plan = plan_outputs(figure=args.plot, force=args.force)
    try:
        data = datasets.load(args.name)
    except KeyError as error:
        raise InputFileError(str(error.args[0]) if error.args else str(error)) from error
    written = plan.write(figure=data.plot)
    report(written, f"{data}\n\n{format_table(data.summary(), index=True)}")
    return 0



def add_parser(commands) -> None:
    data = commands.add_parser(
        "datasets", help="list the IMU data sets, or summarize / plot one",
        description="The R package's IMU Allan variance data sets, shipped inside the package: list them, or "
                    "summarize and plot one.")
    data.add_argument("name", nargs="?", help="data set name, e.g. navchip_av (default: list them all)")
    data.add_argument("--plot", metavar="PNG",
                      help="write the figure to this file, format from its extension: png, pdf, svg, ... (default: none)")
    data.add_argument("--force", action="store_true", help="replace existing output files (default: refuse)")
    data.set_defaults(handler=run)
