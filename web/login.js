// The code page: POST /api/login {code}; the server answers with an HttpOnly cookie, then
// every page opens. Wrong codes are limited per address (429 says how long to wait).
'use strict';

async function enter() {
  const result = document.getElementById('result');
  const code = document.getElementById('code').value;
  result.className = '';
  result.textContent = 'Checking...';
  const res = await fetch('/api/login', {method: 'POST', headers: {'Content-Type': 'application/json'}, body: JSON.stringify({code: code})});
  const answer = await res.json();
  if (res.status === 200) {
    const teacher = new URLSearchParams(window.location.search).has('teacher');
    window.location.href = teacher && answer.role === 'teacher' ? '/teacher' : '/';
    return;
  }
  result.className = 'error';
  result.textContent = answer.error;
}

document.getElementById('enter').onclick = enter;
document.getElementById('code').addEventListener('keydown', (e) => { if (e.key === 'Enter') enter(); });
