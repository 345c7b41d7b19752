#!/usr/bin/env python3
"""A TCP relay that counts the bytes each way between a ParaView client and pvserver.

    byte_relay.py --listen PORT --target PORT --control PATH [--ready-file PATH]

Accepts connections on 127.0.0.1:PORT and forwards each to 127.0.0.1:TARGET
(pvserver), counting bytes client->server and server->client over all
connections. A client script asks for the running totals on the UNIX socket
PATH: it sends one line, "totals", and reads back one line,
"<client_to_server> <server_to_client> <connections>". Differences of two
readings give the bytes of one step (RelayCounter in clientserver.py).

Run it only inside the loopback-only network namespace of the tests
(Testing/Scripts/netns.sh): it binds 127.0.0.1 only, but pvserver behind it
listens on every interface. Single-threaded (selectors); runs until SIGTERM.
"""
import argparse
import os
import selectors
import signal
import socket
import sys

CHUNK = 1 << 16


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--listen", type=int, required=True)
    parser.add_argument("--target", type=int, required=True)
    parser.add_argument("--control", required=True, help="UNIX socket path for totals")
    parser.add_argument("--ready-file", help="written once the relay accepts connections")
    args = parser.parse_args()

    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    sel = selectors.DefaultSelector()
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    listener.bind(("127.0.0.1", args.listen))
    listener.listen(8)
    listener.setblocking(False)
    sel.register(listener, selectors.EVENT_READ, ("listen", None))

    if os.path.exists(args.control):
        os.unlink(args.control)
    control = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    control.bind(args.control)
    control.listen(4)
    control.setblocking(False)
    sel.register(control, selectors.EVENT_READ, ("control", None))

    totals = {"c2s": 0, "s2c": 0, "connections": 0}
    peers = {}  # socket -> (peer socket, direction key of bytes read from it)

    def close_pair(sock):
        other = peers.pop(sock, (None, None))[0]
        for s in (sock, other):
            if s is None:
                continue
            peers.pop(s, None)
            try:
                sel.unregister(s)
            except (KeyError, ValueError):
                pass
            s.close()

    if args.ready_file:
        with open(args.ready_file, "w") as ready:
            ready.write("%d\n" % os.getpid())

    while True:
        for key, _ in sel.select(timeout=1.0):
            kind, _ = key.data
            sock = key.fileobj
            if kind == "listen":
                client, _ = sock.accept()
                server = socket.create_connection(("127.0.0.1", args.target))
                for s in (client, server):
                    s.setblocking(True)
                    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
                peers[client] = (server, "c2s")
                peers[server] = (client, "s2c")
                sel.register(client, selectors.EVENT_READ, ("data", None))
                sel.register(server, selectors.EVENT_READ, ("data", None))
                totals["connections"] += 1
            elif kind == "control":
                conn, _ = sock.accept()
                conn.setblocking(True)
                conn.settimeout(5)
                try:
                    conn.recv(64)
                    conn.sendall(("%d %d %d\n" % (totals["c2s"], totals["s2c"],
                                                  totals["connections"])).encode())
                except OSError:
                    pass
                conn.close()
            else:
                if sock not in peers:
                    continue
                other, direction = peers[sock]
                try:
                    data = sock.recv(CHUNK)
                except OSError:
                    data = b""
                if not data:
                    close_pair(sock)
                    continue
                totals[direction] += len(data)
                try:
                    other.sendall(data)
                except OSError:
                    close_pair(sock)


if __name__ == "__main__":
    main()
