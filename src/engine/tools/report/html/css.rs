//! The report's style sheet: screen and A4 print.

pub(super) const CSS: &str = "
:root{--before:#e67828;--after:#2896e6;--muted:#777}
*{-webkit-print-color-adjust:exact;print-color-adjust:exact;box-sizing:border-box}
body{font:14px/1.45 system-ui,-apple-system,'Segoe UI',Roboto,'DejaVu Sans',Arial,sans-serif;color:#1d1d1d;max-width:960px;margin:24px auto;padding:0 16px;background:#fff}
h1{font-size:24px;margin:0 0 2px}
h1 small{display:block;font-size:16px;font-weight:normal;color:#444}
h2{font-size:18px;border-bottom:1px solid #ccc;padding-bottom:3px;margin:28px 0 8px}
h3{font-size:15px;margin:16px 0 6px}
table{border-collapse:collapse;margin:6px 0 10px}
th,td{padding:2px 8px;border-bottom:1px solid #e4e4e4;text-align:left;vertical-align:top}
th{font-weight:600;background:#f4f4f4}
td.n,th.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
table.meta th{background:none;width:11em}
table.small{font-size:12px}
.mono{font-family:ui-monospace,'DejaVu Sans Mono',Menlo,Consolas,monospace;font-size:12px;word-break:break-all}
td.key{font-family:ui-monospace,'DejaVu Sans Mono',Menlo,Consolas,monospace;white-space:nowrap}
pre{font-size:12px;margin:4px 0;background:#f7f7f7;padding:6px 8px;overflow-x:auto}
.headline{border:1px solid #ccc;border-radius:6px;padding:10px 14px;margin:8px 0}
.big{display:inline-block;font-size:26px;font-weight:600;margin-right:28px;white-space:nowrap}
.ratio{color:#1f6fae;font-size:16px;font-weight:normal;margin-left:4px}
.verdict{font-size:22px;font-weight:700;padding:6px 12px;border-radius:4px;margin:8px 0}
.verdict.pass{background:#e3f4e6;color:#16662a;border-left:6px solid #2e9d4a}
.verdict.fail{background:#fbe4e4;color:#9b1c1c;border-left:6px solid #d33}
.verdict.unchecked{background:#f1f1f1;color:#555;border-left:6px solid #999}
.warn{background:#fff4e0;border-left:4px solid #e6aa28;padding:6px 10px;margin:8px 0}
.muted,.marked{color:var(--muted)}
.b{color:#b85a15}.a{color:#1f6fae}
figure{margin:12px 0}
figcaption{font-size:13px;color:#444;margin-top:2px}
svg.plot{max-width:100%;height:auto;display:block}
.grid2{display:grid;grid-template-columns:1fr 1fr;gap:14px}
ul{margin:4px 0 8px;padding-left:22px}
footer{margin-top:32px;border-top:1px solid #ccc;font-size:12px;color:#555}
@page{size:A4;margin:14mm 12mm}
@media print{
body{max-width:none;margin:0;padding:0;font-size:10.5px}
h2{break-after:avoid;margin-top:18px}
figure,.headline,table.keep,tr{break-inside:avoid}
.big{font-size:20px}
pre,.mono{font-size:10px}
}
";
