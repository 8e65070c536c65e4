"""penumbra-client: submit, follow and fetch renders from a shell.

    penumbra-client render scene.json -o out.exr     # uploads the files it names, waits, saves
    penumbra-client submit scene.json                # prints the job's id
    penumbra-client wait JOB -o out.png
    penumbra-client list [--state queued]
    penumbra-client cancel JOB

The server and token come from --url/--token or $PENUMBRA_URL/$PENUMBRA_TOKEN.
"""
from __future__ import annotations

import argparse
import json
import sys

from .client import Client
from .errors import InvalidRequest, PenumbraError


def _save(client: Client, job, output: str) -> None:
    fmt = "png" if output.lower().endswith(".png") else "exr"
    data = client.result(job, format=fmt, as_array=False)
    with open(output, "wb") as f:
        f.write(data)
    print(f"{output}: {len(data)} bytes", file=sys.stderr)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="penumbra-client", description=__doc__.splitlines()[0])
    parser.add_argument("--url")
    parser.add_argument("--token")
    sub = parser.add_subparsers(dest="command", required=True)
    for name in ("render", "submit"):
        p = sub.add_parser(name)
        p.add_argument("scene", help="scene .json or .glb")
        p.add_argument("--priority", type=int)
        if name == "render":
            p.add_argument("-o", "--output", required=True)
    p = sub.add_parser("wait")
    p.add_argument("job")
    p.add_argument("-o", "--output")
    p = sub.add_parser("list")
    p.add_argument("--state")
    p = sub.add_parser("cancel")
    p.add_argument("job")
    args = parser.parse_args(argv)
    client = Client(args.url, args.token)
    try:
        if args.command in ("render", "submit"):
            job = client.submit(args.scene, priority=args.priority)
            if args.command == "submit":
                print(job["id"])
                return 0
            client.wait(job)
            _save(client, job, args.output)
        elif args.command == "wait":
            record = client.wait(args.job)
            if args.output:
                _save(client, record, args.output)
            else:
                print(json.dumps(record, indent=2))
        elif args.command == "list":
            for record in client.list(state=args.state):
                print(f"{record['id']}  {record['state']:<9}  {100 * (record.get('progress') or 0):5.1f}%")
        elif args.command == "cancel":
            print(client.cancel(args.job).get("state", ""))
        return 0
    except InvalidRequest as e:
        print(f"penumbra-client: {e}", file=sys.stderr)
        return 2
    except PenumbraError as e:
        print(f"penumbra-client: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
