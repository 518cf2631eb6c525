"""The report's static assets: the page's style sheet and the colours and CSS classes it gives part families and
verdicts. Constants only; nothing here builds markup from data.
"""
from __future__ import annotations

FAMILY_COLORS = {"hull": (0.62, 0.72, 0.82), "link": (0.95, 0.65, 0.25), "fin": (0.24, 0.43, 0.57),
                 "spool": (0.89, 0.34, 0.18), "mount": (0.46, 0.69, 0.25), "guide": (0.63, 0.42, 0.84),
                 "cradle": (0.86, 0.74, 0.30), "ballast": (0.45, 0.47, 0.52), "bought": (0.33, 0.33, 0.36)}
OTHER_COLOR = (0.7, 0.7, 0.7)
VERDICT_CLASS = {"PASS": "pass", "INFO": "info", "NOT_EVALUATED": "na", "WARN": "warn", "FAIL": "fail"}

CSS = """
:root{--ink:#1f2a37;--muted:#6b7685;--line:#e3e7ed;--bg:#f5f7fa;--card:#fff;--accent:#1f5f99;
--pass:#2a9d5c;--warn:#d68910;--fail:#c0392b;--info:#2874a6;--na:#8a94a3}
*{box-sizing:border-box}
html{scroll-behavior:smooth}
body{margin:0;font:15px/1.5 system-ui,-apple-system,"Segoe UI",Roboto,"Helvetica Neue",Arial,sans-serif;
color:var(--ink);background:var(--bg)}
header.top{background:linear-gradient(120deg,#0e2a47,#1f5f99 60%,#2f86c4);color:#fff;padding:28px 40px 22px}
header.top h1{margin:0 0 4px;font-size:28px;font-weight:650;letter-spacing:.2px}
header.top .sub{opacity:.85;font-size:14px}
nav{position:sticky;top:0;z-index:5;background:#fff;border-bottom:1px solid var(--line);padding:0 32px;
display:flex;flex-wrap:wrap;gap:2px;box-shadow:0 1px 4px rgba(0,0,0,.04)}
nav a{color:var(--ink);text-decoration:none;padding:11px 12px;font-size:14px;border-bottom:2px solid transparent}
nav a:hover{color:var(--accent);border-bottom-color:var(--accent)}
main{max-width:1280px;margin:0 auto;padding:8px 32px 48px}
section{background:var(--card);border:1px solid var(--line);border-radius:10px;padding:20px 26px;margin:22px 0;
scroll-margin-top:56px}
section h2{margin:0 0 12px;font-size:21px;font-weight:650}
section h3{margin:20px 0 8px;font-size:16px}
.lead{color:#3b4754;margin:4px 0 14px}
.muted{color:var(--muted)}
code{font:12.5px/1.3 ui-monospace,"SFMono-Regular",Menlo,Consolas,monospace;background:#f0f3f7;padding:1px 4px;border-radius:3px}
.tiles{display:grid;grid-template-columns:repeat(auto-fill,minmax(190px,1fr));gap:12px;margin:8px 0 6px}
.tile{border:1px solid var(--line);border-left:4px solid var(--accent);border-radius:8px;padding:10px 14px;background:#fbfcfe}
.tile.good{border-left-color:var(--pass)}.tile.warn{border-left-color:var(--warn)}.tile.bad{border-left-color:var(--fail)}
.tile.muted{border-left-color:var(--na)}
.tlabel{font-size:12px;text-transform:uppercase;letter-spacing:.6px;color:var(--muted)}
.tvalue{font-size:22px;font-weight:650;margin:2px 0}
.tsub{font-size:12.5px;color:var(--muted)}
figure{margin:10px 0 18px}
figure img{display:block;max-width:100%;height:auto;margin:0 auto}
figure.wide img{width:100%;max-width:1200px}
figure.fitplot img{width:auto;max-width:100%;max-height:640px}
figcaption{font-size:13.5px;color:#3b4754;margin-top:6px;max-width:1100px}
.swatch{display:inline-block;width:11px;height:11px;border-radius:2px;margin:0 4px -1px 0;border:1px solid rgba(0,0,0,.2)}
.cards{display:grid;grid-template-columns:repeat(auto-fill,minmax(228px,1fr));gap:14px}
.card{border:1px solid var(--line);border-radius:8px;overflow:hidden;background:linear-gradient(#f7f9fc,#fff 60%)}
.card img{display:block;width:100%;height:auto;background:radial-gradient(circle at 50% 45%,#fff,#eef2f7)}
.cbody{padding:8px 12px 12px;font-size:13.5px;border-top:1px solid var(--line)}
.cname{font-weight:650;font-size:14.5px;word-break:break-word}
.cmeta{color:var(--muted);font-size:12.5px}
.mass{font-weight:650}
.cset{color:var(--muted);font-size:12px;margin-top:3px}
.tablewrap{overflow-x:auto}
table{border-collapse:collapse;width:100%;font-size:13.5px}
th,td{padding:6px 9px;border-bottom:1px solid var(--line);text-align:left;vertical-align:top}
th{background:#f3f6f9;font-weight:600;position:sticky;top:0}
td.num,th.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
tbody tr:hover{background:#f7fafd}
tr.row-fail{background:#fdecea}tr.row-warn{background:#fef5e7}tr.row-na{background:#f6f7f9}
tr.row-fail td:first-child{border-left:4px solid var(--fail)}tr.row-warn td:first-child{border-left:4px solid var(--warn)}
tr.row-pass td:first-child{border-left:4px solid var(--pass)}tr.row-info td:first-child{border-left:4px solid var(--info)}
tr.row-na td:first-child{border-left:4px solid var(--na)}
.badge{display:inline-block;padding:1px 8px;border-radius:10px;font-size:12px;font-weight:600;color:#fff;white-space:nowrap}
.badge.pass{background:var(--pass)}.badge.warn{background:var(--warn)}.badge.fail{background:var(--fail)}
.badge.info{background:var(--info)}.badge.na{background:var(--na)}
.tile .badge{font-size:16px;padding:2px 12px}
.detail{color:var(--muted);font-size:12px;margin-top:2px}
.margin{min-width:90px}
.mbar{display:block;height:4px;border-radius:2px;margin-top:3px;margin-left:auto}
.mbar.pos{background:var(--pass)}.mbar.neg{background:var(--fail)}
.notice{border-radius:8px;padding:10px 14px;margin:8px 0;font-size:14px}
.notice.missing{background:#f4f6f8;border:1px dashed #b7c0cc;color:#44505e}
.notice.info{background:#eaf2fb;border:1px solid #c6dbf1}
.notice.warn{background:#fef5e7;border:1px solid #f5d7a1}
table.audit td:nth-child(3){min-width:150px}table.audit td:nth-child(8){min-width:210px}
table.rules td:first-child{min-width:260px}table.rules td:last-child{min-width:260px}table.rules td:nth-child(3){white-space:nowrap}
footer{color:var(--muted);font-size:12.5px;text-align:center;padding:10px 0 30px}
"""
